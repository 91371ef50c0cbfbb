"""A distorting lens in front of the renderer: the scene is drawn by a pinhole of the same
focal length whose image covers every sensor pixel's ray (`Camera.pinhole_cover`), then
resampled onto the sensor's grid, each pixel at its own ray (`Camera.rays`), so that
frames.h5 holds what the sensor behind that lens records (docs/geometry.md "Lens
distortion"). Stars, points, are not resampled: each is projected through the lens onto
the sensor's sky pixels afterwards (stars.add_stars with the lens's camera).

Radiance: bilinear between the four pinhole samples around the ray. Depth (along the
boresight): bilinear in inverse depth, which is exact on a plane (1/Z is affine in the
image), over the terrain samples only; a pixel whose four samples are mostly sky is sky.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator

import numpy as np

from ..geometry.camera import Camera, CameraPose
from ..scene.stars import StarField, add_stars
from .draw import Frame, TerrainRenderer


class LensResampling:
    """Where each sensor pixel's ray falls in the pinhole cover's image: the flat index of
    the sample above-left of it and the four bilinear weights, computed once per camera."""

    def __init__(self, camera: Camera, cover: Camera):
        a, b = camera.rays()
        f = cover.focal_px
        col = f * a + (cover.width / 2 - 0.5)  # continuous pixel indices in the cover's image
        row = f * b + (cover.height / 2 - 0.5)
        col0, row0 = np.floor(col), np.floor(row)
        if col0.min() < 0 or row0.min() < 0 or col0.max() + 1 >= cover.width or row0.max() + 1 >= cover.height:
            raise ValueError(f"{cover.width} x {cover.height} pinhole image does not cover the lens's rays")
        fx, fy = col - col0, row - row0
        self.shape = (camera.height, camera.width)
        self.cover_width = cover.width
        self.index = (row0 * cover.width + col0).astype(np.int64)
        self.weights = [(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy]  # corners 00, 01, 10, 11

    def _corners(self, image: np.ndarray) -> list[np.ndarray]:
        flat = np.ascontiguousarray(image).reshape(-1)
        w = self.cover_width
        return [flat[self.index + offset] for offset in (0, 1, w, w + 1)]

    def radiance(self, radiance: np.ndarray) -> np.ndarray:
        """(H, W) float32: bilinear."""
        corners = self._corners(radiance)
        return sum(w * c for w, c in zip(self.weights, corners)).astype(np.float32)

    def depth(self, depth_m: np.ndarray) -> np.ndarray:
        """(H, W) float32 depth along the boresight, 0 = sky: bilinear in inverse depth over
        the terrain samples (mean_depth)."""
        inverse = np.zeros(self.shape)
        terrain_weight = np.zeros(self.shape)
        for w, d in zip(self.weights, self._corners(depth_m)):
            d = d.astype(np.float64)
            terrain = d > 0
            inverse += np.where(terrain, w / np.where(terrain, d, 1.0), 0.0)
            terrain_weight += np.where(terrain, w, 0.0)
        return mean_depth(inverse, terrain_weight)


def mean_depth(inverse_weighted: np.ndarray, terrain_weight: np.ndarray) -> np.ndarray:
    """float32 depth (m, 0 = sky) of pixels made of weighted samples, from the weighted sum
    of the terrain samples' inverse depths and the sum of their weights (all samples' sum
    to 1): the inverse of the terrain's mean inverse depth, exact on a plane (1/Z is affine
    in the image); sky where the terrain's weights sum to less than a half."""
    terrain = terrain_weight >= 0.5
    return np.where(terrain, terrain_weight / np.where(terrain, inverse_weighted, 1.0), 0.0).astype(np.float32)


class WrappedRenderer:
    """A renderer (`inner`) whose frames each pass through `_after(frame, pose)`: `render`,
    `render_sequence` (one drawn ahead, as the inner's), `backend`, `gl_renderer` as the
    inner's; it owns the inner renderer."""

    def __init__(self, inner):
        self.renderer = inner
        self.backend, self.gl_renderer = inner.backend, inner.gl_renderer

    def _after(self, frame: Frame, pose: CameraPose) -> Frame:
        raise NotImplementedError

    def render(self, pose: CameraPose) -> Frame:
        return self._after(self.renderer.render(pose), pose)

    def render_sequence(self, poses: Iterable[CameraPose]) -> Iterator[Frame]:
        drawn = deque()  # the poses handed to the renderer, whose frames come back in order

        def remembered():
            for pose in poses:
                drawn.append(pose)
                yield pose

        for frame in self.renderer.render_sequence(remembered()):
            yield self._after(frame, drawn.popleft())

    def close(self) -> None:
        self.renderer.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class LensRenderer(WrappedRenderer):
    """A TerrainRenderer drawing the pinhole cover of `camera` (without stars), its frames
    resampled onto `camera`'s sensor and `stars` (None: none) added through the lens."""

    def __init__(self, renderer: TerrainRenderer, camera: Camera, stars: StarField | None = None):
        super().__init__(renderer)
        self.camera, self.stars = camera, stars
        self.resampling = LensResampling(camera, renderer.camera)

    def _after(self, frame: Frame, pose: CameraPose) -> Frame:
        r = self.resampling
        radiance, depth = r.radiance(frame.radiance), r.depth(frame.depth_m)
        if self.stars is not None:
            radiance = add_stars(radiance, depth, self.stars, self.camera, pose)
        return Frame(radiance, depth, frame.n_tiles, frame.n_triangles)


def lens_renderer(tiles, camera: Camera, *args, **kwargs) -> TerrainRenderer | LensRenderer:
    """TerrainRenderer(tiles, camera, ...)'s frames as `camera`'s sensor records them: the
    renderer itself for a pinhole, else a LensRenderer around a renderer of its pinhole cover."""
    if camera.distortion.is_pinhole:
        return TerrainRenderer(tiles, camera, *args, **kwargs)
    stars = kwargs.pop("stars", None)
    return LensRenderer(TerrainRenderer(tiles, camera.pinhole_cover(), *args, **kwargs), camera, stars)
