"""Prediction files, read and checked before any scoring (docs/tasks.md "Formats").

A table task's predictions are one CSV: a row per landing and time, columns `scenario`,
`id`, `t_s` (the pose's time, s) and the task's values, units in their names. Lines that
start with `#` before the header are the predictor's notes, `# key: value` (a baseline
writes `method`, `run_time_s`, `events_s`). Each check names the file, the column and
what was expected: a missing column, a value that is not a finite number, a landing or
time not in the dataset, a missing or repeated one, values a thousand times off.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from .poses import TIME_TOLERANCE_S

KEYS = ("scenario", "id", "t_s")
SCALE_LIMIT = 30.0  # a column whose typical size is this far from the truth's is refused as a unit slip


class PredictionError(ValueError):
    """A prediction file that cannot be scored: the message names the file and what is wrong."""


def read_notes(lines: list[str]) -> dict[str, str]:
    """The `# key: value` lines at the top of a prediction CSV."""
    notes = {}
    for line in lines:
        key, colon, value = line.lstrip("#").partition(":")
        if colon:
            notes[key.strip()] = value.strip()
    return notes


def read_table(path: str | os.PathLike, columns: tuple[str, ...], optional: tuple[str, ...] = ()) -> tuple:
    """({(scenario, id): (t (n,) s, values (n, len(columns + given optional)))}, the optional
    columns given, notes): rows in the file's order per landing."""
    path = Path(path)
    if not path.is_file():
        raise PredictionError(f"{path}: no such prediction file")
    text = path.read_text().splitlines()
    notes_end = next((i for i, line in enumerate(text) if not line.startswith("#")), len(text))
    rows = list(csv.reader(text[notes_end:]))
    if not rows:
        raise PredictionError(f"{path}: no header; expected the columns {', '.join(KEYS + columns)}")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in KEYS + columns if c not in header]
    if missing:
        raise PredictionError(f"{path}: missing column {', '.join(missing)}; expected {', '.join(KEYS + columns)} "
                              f"(and optionally {', '.join(optional) or 'nothing else'})")  # fmt: skip
    given = tuple(c for c in optional if c in header)
    wanted = [header.index(c) for c in ("t_s",) + columns + given]
    grouped: dict[tuple[str, int], list] = {}
    for line, row in enumerate(rows[1:], start=notes_end + 2):
        if len(row) != len(header):
            raise PredictionError(f"{path}: line {line} has {len(row)} fields, expected {len(header)}")
        try:
            key = (row[header.index("scenario")].strip(), int(row[header.index("id")]))
            values = [float(row[i]) for i in wanted]
        except ValueError as exc:
            raise PredictionError(f"{path}: line {line}: expected an integer id and numbers ({exc})") from None
        bad = [name for name, v in zip(("t_s",) + columns + given, values) if not np.isfinite(v)]
        if bad:
            raise PredictionError(f"{path}: line {line}: {', '.join(bad)} is not a finite number ({row})")
        grouped.setdefault(key, []).append(values)
    table = {key: (np.array(v)[:, 0], np.array(v)[:, 1:]) for key, v in grouped.items()}
    return table, given, read_notes(text[:notes_end])


def check_landings(path, given: set, expected: set) -> None:
    """Every expected landing predicted, and no other."""
    name = lambda keys: ", ".join(f"{s} {i:04d}" for s, i in sorted(keys)[:5]) + (" ..." if len(keys) > 5 else "")  # noqa: E731
    if missing := expected - given:
        raise PredictionError(f"{path}: no prediction for {len(missing)} landing(s): {name(missing)}")
    if extra := given - expected:
        raise PredictionError(f"{path}: {len(extra)} landing(s) not in the dataset (or not in the split): "
                              f"{name(extra)}")  # fmt: skip


def match_times(path, key: tuple[str, int], t_given: np.ndarray, t_expected: np.ndarray) -> np.ndarray:
    """Row of t_given for each expected time (the rows reordered); refuses missing, repeated
    and unexpected times, and names a time given in ms."""
    where = f"{path}: {key[0]} {key[1]:04d}"
    order = np.argsort(t_given, kind="stable")
    sorted_t = t_given[order]
    if len(sorted_t) > 1 and (np.diff(sorted_t) <= TIME_TOLERANCE_S).any():
        twice = sorted_t[1:][np.diff(sorted_t) <= TIME_TOLERANCE_S][0]
        raise PredictionError(f"{where}: t_s = {twice:g} s is given twice")
    n = max(len(sorted_t), 1)
    padded = sorted_t if len(sorted_t) else np.array([np.inf])
    after = np.clip(np.searchsorted(padded, t_expected), 0, n - 1)
    before = np.clip(after - 1, 0, n - 1)
    at = np.where(np.abs(padded[before] - t_expected) <= np.abs(padded[after] - t_expected), before, after)
    near = np.abs(padded[at] - t_expected)
    if (missing := near > TIME_TOLERANCE_S).any():
        hint = ""
        if len(t_given) and np.allclose(np.sort(t_given)[: len(t_expected)] / 1000.0,
                                        t_expected[: len(t_given)], atol=1e-3):  # fmt: skip
            hint = " (t_s looks like milliseconds: expected seconds)"
        first = t_expected[missing][:3]
        raise PredictionError(f"{where}: {int(missing.sum())} of {len(t_expected)} times have no prediction, first "
                              f"{', '.join(f'{t:g}' for t in first)} s{hint}; expected a row at every scored pose "
                              "(docs/tasks.md)")  # fmt: skip
    if len(t_given) > len(t_expected):
        unused = np.setdiff1d(np.arange(len(t_given)), at)
        raise PredictionError(f"{where}: t_s = {sorted_t[unused[0]]:g} s is not a scored pose's time "
                              "(docs/tasks.md lists them)")  # fmt: skip
    return order[at]


def check_scale(path, column: str, unit: str, predicted: np.ndarray, truth: np.ndarray) -> None:
    """Refuse a column whose typical size (the median of its nonzero magnitudes) is over
    SCALE_LIMIT times the truth's or under its inverse: a unit slip (mm for m, ms for s)."""
    p, t = np.abs(np.ravel(predicted)), np.abs(np.ravel(truth))
    p, t = p[p > 0], t[t > 0]
    if not len(p) or not len(t):
        return
    ratio = float(np.median(p) / np.median(t))
    if not 1.0 / SCALE_LIMIT <= ratio <= SCALE_LIMIT:
        raise PredictionError(f"{path}: {column}: typical value {np.median(p):.4g} is {ratio:.3g} times the truth's "
                              f"({np.median(t):.4g} {unit}): expected {unit} (a unit off by 1000?)")  # fmt: skip


def write_table(path: str | os.PathLike, columns: tuple[str, ...], rows: list[tuple], notes: dict) -> None:
    """A prediction CSV: the notes as `# key: value` lines, the header, the rows
    (scenario, id, t_s, values...), floats written exactly (repr)."""
    from ..formats.atomic import atomic_output

    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        for key, value in notes.items():
            fh.write(f"# {key}: {value}\n")
        writer = csv.writer(fh)
        writer.writerow(KEYS + columns)
        for scenario, id_, *values in rows:
            writer.writerow([scenario, int(id_), *(repr(float(v)) for v in values)])
