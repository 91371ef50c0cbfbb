"""The benchmarks' one entry point: a named benchmark with its own options, the quick set,
or the list (bench/README.md says what each measures and which figure it backs).

  python bench/run.py --list                # each benchmark and what it measures
  python bench/run.py NAME [OPTIONS...]     # one benchmark: bench/NAME.py with its options
  python bench/run.py --quick               # the quick set: no built dataset, ~30 s on 2 cores
"""

from __future__ import annotations

import argparse
import ast
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
NOT_BENCHMARKS = ("common", "run")
# The quick set: what each measures without a built dataset, small enough to run in seconds.
QUICK = {
    "emulator": ["--frames", "20", "--repeats", "1"],
    "motion_field": ["--size", "128", "--repeat", "2"],
    "star_field": ["--size", "128", "--frames", "10", "--rounds", "1"],
    "external_poses": ["--scenarios", "descent"],
    "render": ["--size", "128", "--frames", "5"],
}


def benchmarks() -> dict[str, str]:
    """{name: the first sentence of its docstring} of every benchmark in bench/."""
    found = {}
    for path in sorted(BENCH.glob("*.py")):
        if path.stem not in NOT_BENCHMARKS:
            doc = ast.get_docstring(ast.parse(path.read_text())) or ""
            found[path.stem] = " ".join(doc.split("\n\n")[0].split()).removeprefix("Benchmark: ")
    return found


def run(name: str, options: list[str]) -> int:
    start = time.perf_counter()
    status = subprocess.run([sys.executable, str(BENCH / f"{name}.py"), *options]).returncode
    print(f"# bench/run.py: {name} {' '.join(options)}: exit {status} after {time.perf_counter() - start:.0f} s",
          file=sys.stderr)  # fmt: skip
    return status


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("name", nargs="?", help="a benchmark: bench/NAME.py (see --list)")
    parser.add_argument("options", nargs=argparse.REMAINDER, help="the benchmark's own options")
    parser.add_argument("--list", action="store_true", help="list the benchmarks and what each measures")
    parser.add_argument("--quick", action="store_true", help="run the quick set")
    args = parser.parse_args()
    known = benchmarks()
    if args.list:
        width = max(map(len, known))
        for name, what in known.items():
            print(f"{name:<{width}}  {what}")
        return 0
    if args.quick:
        return max(run(name, options) for name, options in QUICK.items())
    if args.name not in known:
        parser.error(f"no benchmark {args.name!r}; expected one of: {', '.join(known)}")
    return run(args.name, args.options)


if __name__ == "__main__":
    sys.exit(main())
