"""`python -m traj2events ...` and the `traj2events` script: the command line (cli.py), or,
where only the reader is installed (numpy, h5py, hdf5plugin: the commands' own imports are
missing), `--version`, a `--help` that says so, and one line for any command (the
workflow's conda environments run the package from the checkout this way)."""

import sys

# cli.build_parser's subcommands (tests/test_cli.py checks they agree), for the reader's --help.
COMMANDS = ("check-config", "base", "sample", "upsample", "poses", "imu", "render", "motion-field", "events",
            "export", "picture", "index", "summary", "overview", "score", "baseline")  # fmt: skip


def main() -> None:
    try:
        from traj2events.cli import run
    except ModuleNotFoundError as exc:  # the base install reads datasets only
        from traj2events import __version__, missing_dependency

        args = sys.argv[1:]
        if args[:1] == ["--version"]:
            print(f"traj2events {__version__}")
            sys.exit(0)
        if not args or args[:1] in (["-h"], ["--help"]):
            print(f"traj2events {__version__}: this install reads built datasets (traj2events.data, "
                  f"traj2events.formats). Its commands ({', '.join(COMMANDS)}) build them, and need the pipeline's "
                  "dependencies: pip install 'traj2events[pipeline]', or bash setup.sh in a checkout.")  # fmt: skip
            sys.exit(0)
        sys.exit(f"error: {missing_dependency(exc)}")
    run()


if __name__ == "__main__":
    main()
