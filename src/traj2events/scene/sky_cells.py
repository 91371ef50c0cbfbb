"""Speed machinery behind scene.stars: the sky cut into cells of equal area (bands of equal
height in z times sectors of equal longitude), so that a frame projects only the stars of
the cells its view cone touches. A 45 deg camera's cone holds ~7 % of the sky; at the
schema's faintest magnitude (V 12, ~3 M stars) the whole-sky projection was most of a
frame's render time (bench/star_field.py)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

N_BANDS, N_SECTORS = 32, 64  # 2048 cells of 2 pi / 1024 sr each


def cell_of(directions: np.ndarray) -> np.ndarray:
    """The cell index of each unit direction (n, 3): band of z, then sector of longitude."""
    band = np.clip(((directions[:, 2] + 1.0) * 0.5 * N_BANDS).astype(np.int64), 0, N_BANDS - 1)
    longitude = np.arctan2(directions[:, 1], directions[:, 0]) % (2.0 * np.pi)
    sector = np.clip((longitude / (2.0 * np.pi) * N_SECTORS).astype(np.int64), 0, N_SECTORS - 1)
    return band * N_SECTORS + sector


@functools.cache
def _cell_geometry() -> tuple[np.ndarray, np.ndarray]:
    """Each cell's centre direction and the angle from it to the farthest of its corners
    and edge midpoints (a cone of that angle holds the cell). Computed once (~1.4 ms: the
    plan asks for it in every render job's size), read-only."""
    z_edges = np.linspace(-1.0, 1.0, N_BANDS + 1)
    phi_edges = np.linspace(0.0, 2.0 * np.pi, N_SECTORS + 1)

    def unit(z, phi):
        z, phi = np.broadcast_arrays(z, phi)
        s = np.sqrt(np.clip(1.0 - z**2, 0.0, None))
        return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1)

    z0, z1 = z_edges[:-1][:, None], z_edges[1:][:, None]
    p0, p1 = phi_edges[:-1][None, :], phi_edges[1:][None, :]
    zm, pm = (z0 + z1) / 2, (p0 + p1) / 2
    centre = unit(zm, pm)
    points = [unit(z, p) for z in (z0, zm, z1) for p in (p0, pm, p1)]
    radius = np.max([np.arccos(np.clip(np.sum(q * centre, axis=-1), -1.0, 1.0)) for q in points], axis=0)
    centre, radius = centre.reshape(-1, 3), radius.reshape(-1)
    centre.flags.writeable = radius.flags.writeable = False
    return centre, radius


def mean_cell_radius_rad() -> float:
    """The cells' mean radius: how far, on average, a cone's cells reach beyond it."""
    return float(_cell_geometry()[1].mean())


@dataclass(frozen=True)
class SkyCells:
    """Offsets of each cell's stars in a field sorted by cell (`start[c]:start[c + 1]`)."""

    start: np.ndarray  # (cells + 1,)
    centre: np.ndarray  # (cells, 3)
    radius_rad: np.ndarray  # (cells,)

    @classmethod
    def sorting(cls, directions: np.ndarray) -> tuple[SkyCells, np.ndarray]:
        """The cells of `directions`, and the order (stable) that groups them by cell."""
        cell = cell_of(directions)
        order = np.argsort(cell, kind="stable")
        start = np.searchsorted(cell[order], np.arange(N_BANDS * N_SECTORS + 1))
        centre, radius = _cell_geometry()
        return cls(start, centre, radius), order

    def slices_in_cone(self, axis: np.ndarray, half_angle_rad: float) -> list[slice]:
        """Slices of the sorted field: the cells any direction within `half_angle_rad` of
        the unit `axis` can fall in (a superset of the stars in the cone), in cell order."""
        reach = np.minimum(half_angle_rad + self.radius_rad, np.pi)
        touched = np.flatnonzero(self.centre @ axis >= np.cos(reach))
        return [slice(self.start[c], self.start[c + 1]) for c in touched if self.start[c + 1] > self.start[c]]
