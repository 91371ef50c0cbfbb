"""Code fingerprints for the workflow's rerun decisions: a rule reruns when the code it
runs changes, not when a comment, a docstring or the command line's help text does.

A stage module's fingerprint hashes its import closure inside this package (every module
it imports, directly or not, at module level or inside functions), each as its syntax
tree without docstrings (comments are not in the tree), plus the package's data files a
module names (the shaders). The YAML files are left out: their values reach the rules as
config, through `params`.
"""

from __future__ import annotations

import ast
import hashlib
from pathlib import Path

PACKAGE = "traj2events"
PACKAGE_DIR = Path(__file__).resolve().parent


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


def imported_modules(name: str, tree: ast.AST, path: Path) -> set[str]:
    """The package's modules that `tree` (module `name`) imports, anywhere in its body."""
    found: set[str] = set()
    package = _package_of(name, path)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == PACKAGE)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != PACKAGE:
                continue
            found.add(target)
            found.update(f"{target}.{a.name}" for a in node.names if module_path(f"{target}.{a.name}"))
    # A submodule import runs its packages' __init__ too.
    for module in list(found):
        parts = module.split(".")
        found.update(".".join(parts[:i]) for i in range(1, len(parts)))
    return {m for m in found if module_path(m) is not None}


def import_closure(name: str) -> list[str]:
    """`name` and every package module it imports, directly or not, sorted."""
    seen: set[str] = set()
    todo = [name]
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        path = module_path(module)
        if path is None:
            raise ValueError(f"{module}: not a module of {PACKAGE}")
        seen.add(module)
        todo.extend(imported_modules(module, ast.parse(path.read_text()), path) - seen)
    return sorted(seen)


def _without_docstrings(tree: ast.AST) -> ast.AST:
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if (
                body
                and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)
            ):
                node.body = body[1:] or [ast.Pass()]
    return tree


def data_files(tree: ast.AST, folder: Path = PACKAGE_DIR) -> list[Path]:
    """Package data (files, or the files of a folder) named by a string in the code of a
    module in `folder`; YAML excluded."""
    files: set[Path] = set()
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and node.value
            and len(node.value) < 256  # a file name, not a docstring or a message
            and "/" not in node.value
            and "\n" not in node.value
            and not node.value.startswith(".")
        ):
            candidate = folder / node.value
            if candidate.is_dir() and not (candidate / "__init__.py").exists():
                files.update(p for p in candidate.iterdir() if p.is_file())
            elif candidate.is_file() and candidate.suffix not in (".py", ".yaml"):
                files.add(candidate)
    return sorted(files)


def code_fingerprint(name: str) -> str:
    """16 hex digits that change when the code module `name` runs changes (see above)."""
    digest = hashlib.sha256()
    for module in import_closure(name):
        tree = ast.parse(module_path(module).read_text())
        digest.update(module.encode() + b"\0" + ast.dump(_without_docstrings(tree)).encode() + b"\0")
        for path in data_files(tree, module_path(module).parent):
            digest.update(path.relative_to(PACKAGE_DIR).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]
