"""traj2events: synthetic event-camera datasets from mass-optimal lunar landings."""

try:  # written by setuptools-scm at install time, from the git tags (traj2events.provenance)
    from ._version import __version__
except ImportError:  # a source tree never installed
    __version__ = "0+unknown"


def missing_dependency(exc: ModuleNotFoundError) -> str:
    """The one line for a command run where only the reader is installed (the base install:
    numpy, h5py, hdf5plugin); building datasets needs the `pipeline` extra."""
    return (
        f"{exc.name} is not installed: this command needs the pipeline's dependencies "
        "(pip install 'traj2events[pipeline]', or bash setup.sh in a checkout)"
    )


def models_importable() -> bool:
    """Whether the models can run here (numpy is importable): a Snakemake alone (the
    workflow catalog's lint, `--sdm conda`'s controller) parses the workflow without them,
    and leaves the checks and estimates that run one (the display white against the
    reflectance, the lens's cover, the DEM file, the stars' render cost) to
    `traj2events check-config` and the jobs."""
    import importlib.util

    return importlib.util.find_spec("numpy") is not None
