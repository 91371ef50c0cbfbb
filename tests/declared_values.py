"""Hypothesis strategies for a settings section's every key, drawn across the bounds its
declarations give (settings.declare): the property tests that drive a stage with configs
the check accepts (docs/accuracy.md "End-to-end stress")."""

import typing

import numpy as np
from hypothesis import strategies as st

from normal_floats import SMALLEST, normal_floats
from traj2events.settings.declare import declared_fields

# Caps on the bounds the declarations leave open (a rate's ge=0 and no more), by unit: for
# the events stage, events enough to exercise every law in a 3 x 4 image over 0.4 s, few
# enough to stay a unit test.
OPEN_CAPS = {"Hz": 1e4, "s": 0.05, "ln": 5.0, "cm^-2 s^-1": 1e5, "": 1.0}


def declared_values(cls, normal: bool = False, **caps):
    """A strategy for a section's every key, drawn across its declared bounds (open ones
    capped by unit, OPEN_CAPS; any by `caps`): floats (subnormals included, as the config
    check accepts them; `normal`: 0 or >= 1e-100, for a law's relative bound), tuples of
    floats (as lists, as a config writes them), [low, high] ranges, choices, booleans,
    integers."""
    keys, hints = {}, typing.get_type_hints(cls)
    for f in declared_fields(cls):
        meta, bounds, hint = f.metadata, f.metadata["bounds"], hints[f.name]
        if meta["choices"]:
            keys[f.name] = st.sampled_from(meta["choices"])
        elif hint is bool:
            keys[f.name] = st.booleans()
        elif hint is int:  # (seeds to 2^64 - 1: larger ones failed the jobs writing them to HDF5)
            lo, hi = bounds.get("ge", bounds.get("gt", -1) + 1), bounds.get("le", bounds.get("lt", 2**64) - 1)
            keys[f.name] = st.integers(lo, min(hi, caps.get(f.name, hi)))
        elif hint is float or (typing.get_origin(hint) is tuple and set(typing.get_args(hint)) == {float}):
            floats = _floats(bounds, _cap(f, caps), normal)
            # (a tuple as a config writes it: a list; the sections take either)
            keys[f.name] = floats if hint is float else st.lists(floats, min_size=len(typing.get_args(hint)),
                                                                 max_size=len(typing.get_args(hint)))  # fmt: skip
        elif hint == list[float] and meta["length"]:  # a [low, high] range
            floats = _floats(bounds, _cap(f, caps), normal)
            keys[f.name] = st.lists(floats, min_size=meta["length"], max_size=meta["length"]).map(sorted)
    return st.fixed_dictionaries(keys)


def accepted(cls, normal: bool = False, **caps):
    """A strategy for instances of section `cls` drawn with `declared_values`, those its own
    checks refuse (e.g. a dry mass above the wet mass) left out."""
    return declared_values(cls, normal, **caps).map(lambda keys: _built(cls, keys)).filter(bool)


def _built(cls, keys: dict):
    try:
        return cls(**keys)
    except ValueError:
        return None


def _cap(f, caps: dict) -> float:
    """The largest value to draw for field `f`: the caller's cap, else the unit's cap where
    the declaration sets no upper bound, else none (its declared bound)."""
    if f.name in caps:
        return caps[f.name]
    bounds = f.metadata["bounds"]
    return np.inf if "le" in bounds or "lt" in bounds else OPEN_CAPS.get(f.metadata["unit"], np.inf)


def _floats(bounds: dict, cap: float, normal: bool):
    """Floats inside a declaration's bounds, capped at `cap`; open bounds (`gt`, `lt`) left
    out by Hypothesis itself, so that the search reaches the float next to them (the
    smallest subnormal above gt=0 found issue 71's 112 s shot-noise sort)."""
    hi = min(bounds.get("le", bounds.get("lt", np.inf)), cap)
    lo = bounds.get("ge", bounds.get("gt", -hi))  # no lower bound (a lens's coefficients): as far below 0
    open_lo, open_hi = "gt" in bounds, "lt" in bounds and hi == bounds["lt"]
    if normal and lo == 0 and open_lo:  # gt=0: from the smallest normal float up
        lo, open_lo = SMALLEST[np.float64], False
    # (no inf: the check refuses it before any bound, tests/test_config.py)
    return (normal_floats if normal else st.floats)(lo, hi, exclude_min=open_lo, exclude_max=open_hi,
                                                    allow_infinity=False)  # fmt: skip
