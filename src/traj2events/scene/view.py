"""What a camera sees of the Moon: its view frustum's planes, how far terrain can be seen
above the horizon, and the depth range that brackets what is drawn."""

from __future__ import annotations

import numpy as np

from ..geometry.camera import Camera


def depth_range(dists: np.ndarray, radii: np.ndarray, camera: Camera) -> tuple[float, float]:
    """(znear, zfar) that bracket every drawn tile (centre distances and bounding radii):
    near from the closest bounding sphere (a point at distance d inside the frustum has
    depth >= d cos(half diagonal))."""
    half_diag = np.arctan(np.hypot(camera.width, camera.height) / 2 / camera.focal_px)
    near = max(float(np.min(dists - radii)) * np.cos(half_diag) * 0.99, 1e-3)
    far = float(np.max(dists + radii)) * 1.01 + 1.0
    return near, far


def frustum_planes(camera: Camera) -> np.ndarray:
    """Inward unit normals (4, 3) of the side planes, camera frame (X forward = columns,
    Y right = rows, Z boresight); a point p is inside when planes @ p >= 0."""
    hx = np.arctan(camera.width / 2 / camera.focal_px)
    hy = np.arctan(camera.height / 2 / camera.focal_px)
    return np.array(
        [
            [np.cos(hx), 0, np.sin(hx)],
            [-np.cos(hx), 0, np.sin(hx)],
            [0, np.cos(hy), np.sin(hy)],
            [0, -np.cos(hy), np.sin(hy)],
        ]
    )


def line_of_sight_limit(cam: np.ndarray, radius_m: float, relief_m: float) -> float:
    """Farthest distance at which terrain up to relief_m can be seen from cam (the two
    tangent lengths to the sphere of the Moon: camera's and the peaks')."""
    centre = np.array([0.0, 0.0, radius_m])
    r_cam = float(np.linalg.norm(cam - centre))
    r_low = radius_m - relief_m
    cam_tangent = np.sqrt(max(r_cam**2 - r_low**2, 0.0))
    peak_tangent = np.sqrt(max((radius_m + relief_m) ** 2 - r_low**2, 0.0))
    return float(cam_tangent + peak_tangent)
