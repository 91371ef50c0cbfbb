"""The house's maps stay true: every module is in its folder's map, the modules without a
test file only get fewer, and the code names that docs and docstrings give resolve."""

import ast
import importlib
import re

import pytest

from conftest import ROOT

PACKAGE = ROOT / "src" / "traj2events"
TESTS = ROOT / "tests"

# Modules with no test file of their own (tested through others, or not yet): this list
# only shrinks. A module that gets a test file must leave it.
WITHOUT_TEST_FILE = {
    "defaults", "memory", "progress", "formats/atomic", "formats/exports", "formats/flow", "formats/imu",
    "formats/rounding", "formats/spice", "geometry/motion_pass", "renderer/camera_matrices",
    "renderer/context", "renderer/lens", "renderer/shading_array", "scene/populations",
    "scene/sun", "scene/terrain_kernels", "scene/view", "sensor/ordering", "sensor/parallel",
    "settings/camera", "settings/events", "settings/generate", "settings/imu", "settings/poses",
    "settings/solve", "settings/tree",
    "stages/index", "stages/pictures",
    "stages/render_events", "stages/sample_trajectories",
    "trajectory/flight", "trajectory/legs",
}  # fmt: skip


def modules() -> list[str]:
    """Every module of the package, as folder/name (name alone at the top level)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE).with_suffix("")
        if relative.name not in ("__init__", "__main__", "_version"):  # (_version: written at install)
            found.append(relative.as_posix())
    return found


def has_test_file(module: str) -> bool:
    """Its mirror: tests/<folder>/test_<name>.py (tests/test_<name>.py at the top level)."""
    folder, _, name = module.rpartition("/")
    return (TESTS / folder / f"test_{name}.py").exists()


def test_every_test_file_mirrors_a_module_or_tests_the_whole():
    """A test file in a folder is a module's; at the top, a module's or the whole's (the workflow, the house)."""
    names = set(modules())
    files = [p.relative_to(TESTS) for p in TESTS.rglob("test_*.py") if p.parent != TESTS]
    strays = [f.as_posix() for f in files if f"{f.parent.as_posix()}/{f.stem[5:]}" not in names]
    assert not strays, f"name these after the module they test: {strays}"


@pytest.mark.parametrize("folder", sorted({m.rpartition("/")[0] for m in modules() if "/" in m}))
def test_every_module_is_in_its_folders_map(folder):
    doc = ast.get_docstring(ast.parse((PACKAGE / folder / "__init__.py").read_text())) or ""
    missing = [m for m in modules() if m.rpartition("/")[0] == folder and not re.search(
        rf"^\s+{re.escape(m.rpartition('/')[2])}\b", doc, re.M)]  # fmt: skip
    assert not missing, f"{folder}/__init__.py's map lacks {missing}"


def test_the_architecture_page_names_every_top_level_module_and_folder():
    text = (ROOT / "docs" / "architecture.md").read_text()
    top = [m for m in modules() if "/" not in m] + sorted({m.split("/")[0] + "/" for m in modules() if "/" in m})
    assert not [m for m in top if not re.search(rf"\b{re.escape(m.removesuffix('/'))}(\.py|/)", text)]


def test_the_modules_without_a_test_file_only_get_fewer():
    untested = {m for m in modules() if not has_test_file(m)}
    assert untested <= WITHOUT_TEST_FILE, f"give these a test file: {sorted(untested - WITHOUT_TEST_FILE)}"
    assert not WITHOUT_TEST_FILE - untested, f"these have one now: {sorted(WITHOUT_TEST_FILE - untested)}"


# `a.b` or `a.b.c` whose first part is one of the package's modules or folders.
TOP = sorted({m.split("/")[0] for m in modules()})
REFERENCE = re.compile(rf"`((?:{'|'.join(TOP)})(?:\.[A-Za-z_][A-Za-z0-9_]*)+)(?:\(\))?`")
FILE_SUFFIXES = ("h5", "py", "yaml", "md", "csv", "flo", "png", "mkv", "mp4", "npz", "raw", "aedat4", "tsv")


def resolves(name: str) -> bool:
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            target = importlib.import_module("traj2events." + ".".join(parts[:cut]))
        except ImportError:
            continue
        for attribute in parts[cut:]:
            if not hasattr(target, attribute):
                return False
            target = getattr(target, attribute)
        return True
    return False


def references() -> list[tuple[str, str]]:
    """(where, name) of each code name the docs and the package's docstrings give."""
    texts = [(p.relative_to(ROOT).as_posix(), p.read_text()) for p in sorted((ROOT / "docs").rglob("*.md"))]
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        docs = [ast.get_docstring(n) for n in ast.walk(tree) if isinstance(n, (ast.Module, ast.ClassDef,
                                                                                ast.FunctionDef))]  # fmt: skip
        texts.append((path.relative_to(ROOT).as_posix(), "\n".join(d for d in docs if d)))
    return [(where, m.group(1)) for where, text in texts for m in REFERENCE.finditer(text)
            if m.group(1).rsplit(".", 1)[1] not in FILE_SUFFIXES]  # fmt: skip


def test_every_code_name_in_the_docs_and_docstrings_resolves():
    found = references()
    assert len(found) > 50
    broken = sorted({f"{where}: `{name}`" for where, name in found if not resolves(name)})
    assert not broken, "\n".join(broken)


BENCH = ROOT / "bench"


def bench_imports(path) -> set[str]:
    """The top-level names a benchmark imports (at module level or inside functions)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


def test_no_benchmark_imports_another_or_a_test():
    benches = {p.stem for p in BENCH.glob("*.py")} - {"common"}
    tests = {p.stem for p in TESTS.glob("*.py")}
    crossing = {p.name: sorted(bench_imports(p) & (benches | tests)) for p in BENCH.glob("*.py")}
    assert not {k: v for k, v in crossing.items() if v}
    assert not any(
        "tests" in line and "sys.path" in line for p in BENCH.glob("*.py") for line in p.read_text().split("\n")
    )


def test_the_bench_readme_lists_every_benchmark_and_the_quick_set_exists():
    import sys

    sys.path.insert(0, str(BENCH))
    try:
        from run import QUICK, benchmarks
    finally:
        sys.path.remove(str(BENCH))
        sys.modules.pop("run", None)
    text = (BENCH / "README.md").read_text()
    assert all(f"| `{name}` |" in text for name in benchmarks())
    assert set(QUICK) <= set(benchmarks()) and len(benchmarks()) > 40


def test_no_docs_table_row_is_over_400_characters():
    pages = [*sorted((ROOT / "docs").rglob("*.md")), ROOT / "README.md", ROOT / "bench" / "README.md"]
    long = [f"{p.relative_to(ROOT)}:{n}" for p in pages for n, line in enumerate(p.read_text().split("\n"), 1)
            if line.startswith("|") and len(line) > 400]  # fmt: skip
    assert not long, long


def test_every_decision_record_has_its_four_parts_and_is_linked_from_a_page():
    records = sorted((ROOT / "docs" / "decisions").glob("[0-9][0-9][0-9][0-9]-*.md"))
    pages = "".join(p.read_text() for p in (ROOT / "docs").glob("*.md"))
    assert len(records) >= 6
    for record in records:
        text = record.read_text()
        assert all(f"## {part}" in text for part in ("Context", "Decision", "Consequences")), record.name
        assert "## Options" in text, record.name
        assert f"decisions/{record.name}" in pages, f"no page links {record.name}"
