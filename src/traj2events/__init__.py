"""traj2events: synthetic event-camera datasets from mass-optimal lunar landings."""

__version__ = "0.1.0"
