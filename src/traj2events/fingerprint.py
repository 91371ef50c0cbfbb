"""Code fingerprints for the workflow's rerun decisions: a rule reruns when the code it
runs changes, not when a comment, a docstring or the command line's help text does.

A stage module's fingerprint hashes its import closure inside this package (every module
it imports, directly or not, at module level or inside functions; this module aside),
each as its syntax tree without docstrings (comments are not in the tree), plus the
package's data files a module names (the shaders). The YAML files are left out: their
values reach the rules as config, through `params`.

Each source text is parsed once per process (`read_source`, keyed by the text): the
Snakefile asks for 15 rules' fingerprints, whose closures share most modules. Across
processes the parses are stored in the user's cache (`CACHE_DIR`, one file per text, keyed
by its hash, this module's and Python's version): every Snakemake invocation needs them,
and parsing the package's ~100 modules took ~0.8 s of each.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import json
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

PACKAGE = "traj2events"
PACKAGE_DIR = Path(__file__).resolve().parent
# This module names code and computes none of a stage's output (the tile cache imports it
# for its key), and _version.py is the version setuptools-scm writes at each install: left
# out of every closure, so that their changes rerun nothing (a file's version is an
# attribute of provenance, not of its content).
NOT_IN_CLOSURES = {f"{PACKAGE}.fingerprint", f"{PACKAGE}._version"}
CACHE_DIR = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / PACKAGE / "sources"
# A stored parse is this module's, on this Python (whose ast.dump it is): both name its key.
_STORE_SALT = hashlib.sha256(Path(__file__).read_bytes() + sys.version.encode()).digest()


def module_path(name: str) -> Path | None:
    """traj2events.a.b -> src/traj2events/a/b.py (or a/b/__init__.py); None if not a module."""
    parts = name.split(".")[1:]
    base = PACKAGE_DIR.joinpath(*parts)
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _package_of(name: str, path: Path) -> str:
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


@dataclass(frozen=True)
class Source:
    """What the fingerprint needs of one module's text."""

    imports: tuple[tuple[int, str, tuple[str, ...]], ...]  # (level, module, names) of each import
    strings: tuple[str, ...]  # the short one-line strings, which may name a data file
    code: bytes  # the syntax tree without docstrings, dumped


DEFINITIONS = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)  # what may have a docstring


@functools.lru_cache(maxsize=1024)
def read_source(text: str) -> Source:
    """A module's text, parsed once: its imports, its short strings and its code, all
    without its docstrings; from CACHE_DIR where a process stored it."""
    path = CACHE_DIR / hashlib.sha256(_STORE_SALT + text.encode()).hexdigest()
    try:
        stored = json.loads(path.read_text())
        return Source(tuple((level, module, tuple(names)) for level, module, names in stored["imports"]),
                      tuple(stored["strings"]), stored["code"].encode())  # fmt: skip
    except (OSError, ValueError, KeyError, TypeError):  # none stored (or damaged): parse it
        source = parse_source(text)
    _store(path, {"imports": source.imports, "strings": source.strings, "code": source.code.decode()})
    return source


def _store(path: Path, entry: dict) -> None:
    """Write a cache entry whole or not at all; a cache that cannot be written is only slower."""
    part = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".part") as part:
            json.dump(entry, part)
        os.replace(part.name, path)
    except OSError:
        if part is not None:
            Path(part.name).unlink(missing_ok=True)


def parse_source(text: str) -> Source:
    """`read_source`'s parse: imports, short strings and code, docstrings cut."""
    tree = ast.parse(text)
    imports, strings = [], set()
    todo: list[ast.AST] = [tree]
    while todo:  # ast.walk's visit, with each docstring cut before its node's children are seen
        node = todo.pop()
        if isinstance(node, DEFINITIONS) and _has_docstring(node):
            node.body = node.body[1:] or [ast.Pass()]
        if isinstance(node, ast.Import):
            imports.extend((0, a.name, ()) for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            imports.append((node.level, node.module or "", tuple(a.name for a in node.names)))
        elif (
            isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and node.value
            and len(node.value) < 256  # a file name, not a docstring or a message
            and "/" not in node.value
            and "\n" not in node.value
            and not node.value.startswith(".")
        ):
            strings.add(node.value)
        todo.extend(ast.iter_child_nodes(node))
    return Source(tuple(imports), tuple(sorted(strings)), ast.dump(tree).encode())


def _has_docstring(node: ast.AST) -> bool:
    body = node.body
    return (
        bool(body)
        and isinstance(body[0], ast.Expr)
        and isinstance(body[0].value, ast.Constant)
        and isinstance(body[0].value.value, str)
    )


def imported_modules(name: str, source: Source, path: Path) -> set[str]:
    """The package's modules that module `name` (at `path`) imports, anywhere in its body."""
    found: set[str] = set()
    package = _package_of(name, path)
    for level, module, names in source.imports:
        if not level and not names:  # import a.b
            if module.split(".")[0] == PACKAGE:
                found.add(module)
            continue
        if level:
            base = package.split(".")
            base = base[: len(base) - (level - 1)]
            target = ".".join(base + ([module] if module else []))
        else:
            target = module
        if target.split(".")[0] != PACKAGE:
            continue
        found.add(target)
        found.update(f"{target}.{n}" for n in names if module_path(f"{target}.{n}"))
    # A submodule import runs its packages' __init__ too.
    for module in list(found):
        parts = module.split(".")
        found.update(".".join(parts[:i]) for i in range(1, len(parts)))
    return {m for m in found if m not in NOT_IN_CLOSURES and module_path(m) is not None}


def module_source(module: str) -> tuple[Path, Source]:
    """A package module's file and its parsed text."""
    path = module_path(module)
    if path is None:
        raise ValueError(f"{module}: not a module of {PACKAGE}")
    return path, read_source(path.read_text())


def import_closure(name: str) -> list[str]:
    """`name` and every package module it imports, directly or not, sorted."""
    seen: set[str] = set()
    todo = [name]
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        path, source = module_source(module)
        seen.add(module)
        todo.extend(imported_modules(module, source, path) - seen)
    return sorted(seen)


def data_files(source: Source, folder: Path = PACKAGE_DIR) -> list[Path]:
    """Package data (files, or the files of a folder) named by a string in the code of a
    module in `folder`; YAML excluded."""
    files: set[Path] = set()
    for name in source.strings:
        candidate = folder / name
        if candidate.is_dir() and not (candidate / "__init__.py").exists():
            files.update(p for p in candidate.iterdir() if p.is_file())
        elif candidate.is_file() and candidate.suffix not in (".py", ".yaml"):
            files.add(candidate)
    return sorted(files)


def code_fingerprint(name: str) -> str:
    """16 hex digits that change when the code module `name` runs changes (see above)."""
    digest = hashlib.sha256()
    for module in import_closure(name):
        path, source = module_source(module)
        digest.update(module.encode() + b"\0" + source.code + b"\0")
        for data in data_files(source, path.parent):
            digest.update(data.relative_to(PACKAGE_DIR).as_posix().encode() + b"\0" + data.read_bytes())
    return digest.hexdigest()[:16]
