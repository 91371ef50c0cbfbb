"""The OpenGL matrices of the pinhole camera: its clip (projection) matrix and the view
rotation of a pose, the camera at the origin (tiles are drawn relative to it)."""

from __future__ import annotations

import numpy as np

from ..geometry.camera import Camera, CameraPose, opengl_camera_to_world


def projection_matrix(camera: Camera, near_m: float, far_m: float) -> np.ndarray:
    """OpenGL clip matrix of the pinhole camera (principal point at the image centre)."""
    p = np.zeros((4, 4))
    p[0, 0] = 2.0 * camera.focal_px / camera.width
    p[1, 1] = 2.0 * camera.focal_px / camera.height
    p[2, 2] = (far_m + near_m) / (near_m - far_m)
    p[2, 3] = 2.0 * far_m * near_m / (near_m - far_m)
    p[3, 2] = -1.0
    return p


def view_rotation(pose: CameraPose) -> np.ndarray:
    """World -> OpenGL camera, rotation only: the camera sits at the origin (tiles are
    drawn relative to it)."""
    v = np.eye(4)
    v[:3, :3] = opengl_camera_to_world(pose)[:3, :3].T
    return v
