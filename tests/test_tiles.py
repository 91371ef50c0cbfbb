"""Tile grids (tiles.py). Selection and drawing are tested with the renderer (test_render.py)."""

import numpy as np

from traj2events.tiles import _grid_faces


def test_grid_faces_draw_each_cell_as_two_triangles_in_turn():
    n = 5  # vertices per side: 4 x 4 cells
    faces = _grid_faces(n)
    assert faces.shape == (2 * (n - 1) ** 2, 3) and faces.dtype == np.uint32
    rows, cols = np.divmod(faces.astype(int), n)
    for k, (first, second) in enumerate(zip(faces[0::2], faces[1::2])):
        cell = divmod(k, n - 1)  # cells in row-major order
        corners = {(cell[0] + a) * n + cell[1] + b for a in (0, 1) for b in (0, 1)}
        assert set(first) | set(second) == corners  # together: the cell's four corners
        assert len(set(first) & set(second)) == 2  # sharing the diagonal
    # Every triangle has the same winding, so that one cull-face setting fits all.
    signed_area = (rows[:, 1] - rows[:, 0]) * (cols[:, 2] - cols[:, 0]) - (cols[:, 1] - cols[:, 0]) * (
        rows[:, 2] - rows[:, 0]
    )
    assert np.all(signed_area == signed_area[0]) and signed_area[0] != 0
