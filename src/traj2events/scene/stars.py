"""Stars in the black sky, in physical radiance (docs/rendering.md "Stars").

A seeded star field: directions uniform over the sphere (fixed in the inertial frame: the
Moon turns by 0.5 deg/h, nothing over a landing), V magnitudes drawn from the whole sky's
cumulative star counts

    log10 N(< V) = 0.74 + 0.48 V        (stars brighter than V; Allen's Astrophysical
                                          Quantities' counts, within ~15 % for 1 < V < 10)

down to a limiting magnitude. Each star is taken as Sun-like, so its irradiance at the
camera, over the whole spectrum like the renderer's sunlight, is

    E = 1361 W/m^2 10^(-0.4 (V - V_sun)),     V_sun = -26.76 (Willmer 2018)

and it lands on the image split bilinearly over the four pixels around its projection
(sub-pixel motion then changes the pixels smoothly, as a blurred point would), as radiance
E w / Omega_px with Omega_px = cos^3(theta) / f^2 the solid angle of a pixel theta off
the boresight: the power through the aperture is E times its area whatever the pixels.
Only sky pixels (depth 0) receive it: terrain hides the stars behind it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.camera import Camera, CameraPose
from .sky_cells import SkyCells, mean_cell_radius_rad
from .sun import SOLAR_CONSTANT_W_M2

COUNT_LOG10_AT_V0 = 0.74  # log10 N(< V) = COUNT_LOG10_AT_V0 + COUNT_SLOPE V, whole sky
COUNT_SLOPE = 0.48
SUN_V_MAG = -26.76  # apparent V magnitude of the Sun (Willmer 2018, ApJS 236, 47)
BRIGHTEST_V_MAG = -1.46  # Sirius: no star is drawn brighter


def stars_brighter_than(v_mag: float | np.ndarray) -> float | np.ndarray:
    """Expected number of stars brighter than V over the whole sky."""
    return 10.0 ** (COUNT_LOG10_AT_V0 + COUNT_SLOPE * np.asarray(v_mag, dtype=float))


def star_irradiance_w_m2(v_mag: np.ndarray) -> np.ndarray:
    """Whole-spectrum irradiance of a Sun-like star of magnitude V at the Moon, W/m^2."""
    return SOLAR_CONSTANT_W_M2 * 10.0 ** (-0.4 * (np.asarray(v_mag, dtype=float) - SUN_V_MAG))


def view_cone_rad(camera: Camera) -> float:
    """Half-angle of the cone around the boresight that holds the image, one pixel beyond
    its corners (a star's splat reaches the next pixel)."""
    return float(np.arctan(np.hypot(camera.width / 2 + 1, camera.height / 2 + 1) / camera.focal_px))


def stars_in_view(magnitude_limit: float, camera: Camera) -> float:
    """Expected stars a frame projects: the whole sky's count times the share of the sky
    within the view cone widened by a sky cell's mean radius (sky_cells.py)."""
    reach = min(view_cone_rad(camera) + mean_cell_radius_rad(), np.pi)
    return float(stars_brighter_than(magnitude_limit)) * (1.0 - np.cos(reach)) / 2.0


@dataclass(frozen=True)
class StarField:
    """Unit directions (n, 3) in the inertial frame and irradiances (n,) W/m^2; `cells`:
    where drawn, the stars are grouped by sky cell, so that a frame takes only those of the
    cells in its view (sky_cells.py)."""

    directions: np.ndarray
    irradiance_w_m2: np.ndarray
    cells: SkyCells | None = None

    def in_view(self, camera: Camera, pose: CameraPose) -> StarField:
        """The stars of the sky cells the camera's view cone touches (a superset of those in
        the image; all of them without cells)."""
        if self.cells is None:
            return self
        parts = self.cells.slices_in_cone(pose.rotation[:, 2], view_cone_rad(camera))
        if not parts:
            return StarField(self.directions[:0], self.irradiance_w_m2[:0])
        directions = np.concatenate([self.directions[s] for s in parts])
        return StarField(directions, np.concatenate([self.irradiance_w_m2[s] for s in parts]))

    @classmethod
    def draw(cls, magnitude_limit: float, seed: int) -> StarField:
        """The stars brighter than `magnitude_limit`, as many as the counts law expects."""
        rng = np.random.default_rng(np.random.SeedSequence([seed, 0x57A125]))
        n = int(round(float(stars_brighter_than(magnitude_limit))))
        # Inverse of the cumulative count: the k-th brightest of n has N(< V) = u n, u uniform.
        u = rng.uniform(0.0, 1.0, n)
        v_mag = (np.log10(np.maximum(u * n, 1e-300)) - COUNT_LOG10_AT_V0) / COUNT_SLOPE
        v_mag = np.maximum(v_mag, BRIGHTEST_V_MAG)
        z = rng.uniform(-1.0, 1.0, n)
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        s = np.sqrt(1.0 - z**2)
        directions = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
        cells, order = SkyCells.sorting(directions)
        return cls(directions[order], star_irradiance_w_m2(v_mag)[order], cells)


def star_splat(stars: StarField, camera: Camera, pose: CameraPose) -> tuple[np.ndarray, np.ndarray]:
    """The stars in view as (flat pixel indices, radiance W m^-2 sr^-1) pairs, four per
    star (bilinear), before any masking; an index may repeat."""
    stars = stars.in_view(camera.pinhole_cover(), pose)  # a lens's sensor sees its cover's cone at most
    d_cam = stars.directions @ pose.rotation  # inertial -> camera (rotation is camera -> inertial)
    d_cam = d_cam[d_cam[:, 2] > 1e-6]
    irradiance = stars.irradiance_w_m2[stars.directions @ pose.rotation[:, 2] > 1e-6]
    col_row = camera.to_pixel_index(camera.project(d_cam))
    inside = (
        (col_row[:, 0] > -1) & (col_row[:, 0] < camera.width) & (col_row[:, 1] > -1) & (col_row[:, 1] < camera.height)
    )
    lens = camera.distortion
    if not lens.is_pinhole:  # beyond the rays through the image's edges the polynomial folds back
        a_max, b_max = camera.reach()
        inside &= (np.abs(d_cam[:, 0] / d_cam[:, 2]) <= a_max + 1 / camera.focal_px) & (
            np.abs(d_cam[:, 1] / d_cam[:, 2]) <= b_max + 1 / camera.focal_px
        )
    col_row, irradiance, d = col_row[inside], irradiance[inside], d_cam[inside]
    cos_theta = d[:, 2] / np.linalg.norm(d, axis=1)
    radiance = irradiance * camera.focal_px**2 / cos_theta**3  # E / Omega_px
    if not lens.is_pinhole:  # a pixel behind the lens spans 1 / det J of a pinhole's solid angle
        radiance = radiance * lens.determinant(d[:, 0] / d[:, 2], d[:, 1] / d[:, 2])
    j0, i0 = np.floor(col_row[:, 0]).astype(np.int64), np.floor(col_row[:, 1]).astype(np.int64)
    fx, fy = col_row[:, 0] - j0, col_row[:, 1] - i0
    index, value = [], []
    for dj, di, weight in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)), (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        j, i = j0 + dj, i0 + di
        keep = (j >= 0) & (j < camera.width) & (i >= 0) & (i < camera.height)
        index.append(i[keep] * camera.width + j[keep])
        value.append(radiance[keep] * weight[keep])
    return np.concatenate(index), np.concatenate(value)


def star_radiance(stars: StarField, camera: Camera, pose: CameraPose) -> np.ndarray | None:
    """(H, W) float32 radiance of the stars in view, before any masking; None when none is."""
    index, value = star_splat(stars, camera, pose)
    if not index.size:
        return None
    image = np.bincount(index, value, minlength=camera.width * camera.height)
    return image.reshape(camera.height, camera.width).astype(np.float32)


def add_stars(radiance: np.ndarray, depth_m: np.ndarray, stars: StarField, camera: Camera, pose: CameraPose):
    """The frame's radiance with the stars added on its sky pixels (depth 0); the input
    array itself where no star falls on the sky."""
    index, value = star_splat(stars, camera, pose)
    sky = depth_m[index // camera.width, index % camera.width] == 0  # a gather: depth_m may be a strided view
    if not sky.any():
        return radiance
    out = radiance.copy()
    np.add.at(out.reshape(-1), index[sky], value[sky].astype(np.float32))
    return out
