"""S x S supersampling (`render.supersample`): each pixel the mean of S x S samples, drawn
at S times the camera's size with the tiles the camera's own pixels select. It is the
reference that the pixel footprint's prefiltering is measured against (bench/
pixel_integration.py), and an option, at ~S^2 the render time (docs/rendering.md
"Supersampling").

Radiance: the mean of the block's samples, the pixel's area integral. Depth: as the lens
resamples it (lens.mean_depth), the inverse of the terrain samples' mean inverse depth (on
a plane, the depth at the pixel's centre), sky where most samples are sky. Stars, points,
are added after the mean, onto the camera's own sky pixels (stars.add_stars).
"""

from __future__ import annotations

import numpy as np

from ..geometry.camera import Camera, CameraPose
from ..scene.stars import StarField, add_stars
from .draw import Frame, TerrainRenderer
from .lens import LensRenderer, WrappedRenderer, lens_renderer, mean_depth


def block_mean(image: np.ndarray, samples: int) -> np.ndarray:
    """(H, W) float64: the mean of each `samples` x `samples` block of an (H S, W S) image."""
    h, w = image.shape[0] // samples, image.shape[1] // samples
    # The block's rows summed first, along memory: 2x numpy's mean over both axes at once.
    return image.reshape(h, samples, w, samples).sum(axis=1, dtype=np.float64).sum(axis=2) / samples**2


def block_depth(depth_m: np.ndarray, samples: int) -> np.ndarray:
    """(H, W) float32 depth (m, 0 = sky) of each `samples` x `samples` block (lens.mean_depth)."""
    terrain = depth_m > 0
    inverse = np.divide(1.0, depth_m, out=np.zeros(depth_m.shape, np.float32), where=terrain)  # float32: ~6e-8
    return mean_depth(block_mean(inverse, samples), block_mean(terrain, samples))


class Supersampled(WrappedRenderer):
    """A renderer drawing `samples` times `camera`'s size (without stars), its frames
    averaged onto `camera`'s pixels and `stars` (None: none) added."""

    def __init__(
        self, renderer: TerrainRenderer | LensRenderer, camera: Camera, samples: int, stars: StarField | None = None
    ):
        super().__init__(renderer)
        self.camera, self.samples, self.stars = camera, samples, stars

    def _after(self, frame: Frame, pose: CameraPose) -> Frame:
        radiance = block_mean(frame.radiance, self.samples).astype(np.float32)
        depth = block_depth(frame.depth_m, self.samples)
        if self.stars is not None:
            radiance = add_stars(radiance, depth, self.stars, self.camera, pose)
        return Frame(radiance, depth, frame.n_tiles, frame.n_triangles)


def sensor_renderer(
    tiles, camera: Camera, *args, supersample: int = 1, **kwargs
) -> TerrainRenderer | LensRenderer | Supersampled:
    """What `camera`'s sensor records, each pixel from `supersample` x `supersample` samples
    (1: one, lens.lens_renderer's frames): TerrainRenderer(tiles, camera, ...)'s arguments."""
    if supersample == 1:
        return lens_renderer(tiles, camera, *args, **kwargs)
    stars = kwargs.pop("stars", None)
    kwargs.setdefault("lod_camera", camera.pinhole_cover())  # the tiles of the camera's own pixels
    return Supersampled(lens_renderer(tiles, camera.scaled(supersample), *args, **kwargs), camera, supersample, stars)
