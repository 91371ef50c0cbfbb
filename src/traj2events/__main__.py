"""`python -m traj2events ...` and the `traj2events` script: the command line (cli.py), or one
line saying what is missing where only the reader is installed (the workflow's conda
environments run the package from the checkout this way)."""

import sys


def main() -> None:
    try:
        from traj2events.cli import run
    except ModuleNotFoundError as exc:  # the base install reads datasets only
        from traj2events import missing_dependency

        sys.exit(f"error: {missing_dependency(exc)}")
    run()


if __name__ == "__main__":
    main()
