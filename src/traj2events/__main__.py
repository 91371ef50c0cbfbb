"""`python -m traj2events ...`: the command line without its entry-point script (the
workflow's conda environments run the package from the checkout this way)."""

from .cli import run

run()
