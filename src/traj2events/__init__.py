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
