"""Stage 6: the ground-truth motion field of every n-th frame of a trajectory, over the
Moon's sphere (analytic) and, given frames.h5, of the rendered terrain from its depth:
instantaneous flow (px/s) and the exact displacement to the next frame (px); and, from
the same depth, the range meter (slant range along the central pixel) at every pose."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..formats.atomic import atomic_directory
from ..formats.flow import motion_field_file, write_flo
from ..formats.frames import SITE_ATTRS, FramesFile
from ..formats.hdf5 import set_attrs, write_dataset
from ..formats.trajectory import read_trajectory
from ..geometry.camera import Camera
from ..geometry.motion_field import (
    OCCLUDED,
    OUT_OF_VIEW,
    SKY,
    STATUS_NAMES,
    depth_motion,
    field_difference,
    sphere_motion,
)
from ..progress import log
from ..provenance import provenance


def field_layout(h: int, w: int, terrain: bool) -> dict[str, tuple[tuple, type]]:
    """motion_field.h5's per-pixel datasets: name -> (shape of one field, dtype)."""
    layout = {
        "flow_sphere": ((h, w, 2), np.float32),
        "displacement_sphere": ((h, w, 2), np.float32),
        "valid": ((h, w), bool),
        "status_sphere": ((h, w), np.uint8),
    }
    if terrain:
        layout |= {
            "flow_terrain": ((h, w, 2), np.float32),
            "displacement_terrain": ((h, w, 2), np.float32),
            "valid_terrain": ((h, w), bool),
            "status_terrain": ((h, w), np.uint8),
        }
    return layout


def motion_field(
    trajectory: str | os.PathLike,
    camera: Camera,
    moon_radius_m: float,
    every_n_frames: int,
    output: str | os.PathLike,
    flo_dir: str | os.PathLike,
    frames: str | os.PathLike | None = None,
    compression: str = "blosc",
) -> None:
    """Write motion_field.h5 and one .flo per field (the sphere displacement) into flo_dir;
    `compression`: motion_field.h5's fields' (formats.hdf5.COMPRESSIONS)."""
    if every_n_frames < 1:
        raise ValueError(f"motion field: every_n_frames: expected >= 1, got {every_n_frames}")
    if not moon_radius_m > 0:
        raise ValueError(f"motion field: moon_radius_m: expected > 0, got {moon_radius_m}")
    tr = read_trajectory(trajectory)
    if tr.t is None or len(tr.t) < 2:
        raise ValueError(f"{trajectory}: expected poses/t with at least 2 poses")
    rendered = FramesFile(frames) if frames else None
    try:
        if rendered is not None and (rendered.n_poses, *rendered.shape[1:]) != (len(tr.t), camera.height, camera.width):
            raise ValueError(
                f"{frames}: holds {rendered.n_poses} poses' frames of {rendered.shape[2]} x {rendered.shape[1]}, "
                f"expected {len(tr.t)} of {camera.width} x {camera.height} to match {trajectory}"
            )
        picked = np.arange(0, len(tr.t) - 1, every_n_frames)  # each needs its next frame
        n, h, w = len(picked), camera.height, camera.width
        # Per field: sphere minus terrain-true flow where both exist (mean (u, v) and RMS, px/s),
        # and over how many pixels: 0 where none (a view of the sky), whose mean is not a NaN.
        offset_mean = np.zeros((n, 2), np.float32)
        offset_rms = np.zeros(n, np.float32)
        offset_pixels = np.zeros(n, np.int64)
        attrs = {
            "width": w,
            "height": h,
            "fov_deg": camera.fov_deg,
            "focal_px": camera.focal_px,
            "moon_radius_m": moon_radius_m,
            "fps": float(tr.attrs["fps"]),
            "every_n_frames": every_n_frames,
            "scenario": tr.attrs["scenario"],
            "id": int(tr.attrs["id"]),
            **provenance(__name__),
            "status_codes": ", ".join(f"{code} {name}" for code, name in enumerate(STATUS_NAMES)),
            **camera.intrinsics_attrs(),
            # The terrain-true field is the rendered surface's: a real site's products, named.
            **({k: rendered.attrs[k] for k in SITE_ATTRS if k in rendered.attrs} if rendered is not None else {}),
        }
        log(
            f"{trajectory}: {n} fields of {w} x {h} (every {every_n_frames} of {len(tr.t)} poses)"
            + (f", terrain-true from {frames}" if rendered is not None else "")
        )
        next_depth = (-1, None)  # frame k+1's depth, reused as frame k's when every frame is written
        layout = field_layout(h, w, rendered is not None)
        with (
            atomic_directory(flo_dir) as tmp_dir,
            motion_field_file(output, tr.t[picked], picked, layout, compression) as (out, fields),
        ):
            for i, k in enumerate(picked):
                flow, disp, status = sphere_motion(camera, tr.state[k], tr.state[k + 1], moon_radius_m, np.float32)
                fields["flow_sphere"][i], fields["displacement_sphere"][i] = flow, disp
                fields["status_sphere"][i] = status
                fields["valid"][i] = status <= OUT_OF_VIEW  # on the sphere, in front of k+1, this side of the limb
                # The folder is atomic as a whole: its files need no temporary of their own.
                write_flo(Path(tmp_dir) / f"{k:06d}.flo", disp, atomic=False)
                if rendered is not None:
                    depth = next_depth[1] if next_depth[0] == k else rendered.depth_m(rendered.row_of_pose(k))
                    next_depth = (k + 1, rendered.depth_m(rendered.row_of_pose(k + 1)))
                    terrain_flow, disp, terrain_status = depth_motion(
                        camera, tr.state[k], tr.state[k + 1], depth, next_depth[1], dtype=np.float32
                    )
                    fields["flow_terrain"][i], fields["displacement_terrain"][i] = terrain_flow, disp
                    fields["status_terrain"][i] = terrain_status
                    fields["valid_terrain"][i] = terrain_status <= OCCLUDED  # terrain, in front of camera k+1
                    both = (status != SKY) & (terrain_status != SKY)  # sphere and terrain under the pixel
                    offset_pixels[i] = np.count_nonzero(both)
                    if offset_pixels[i]:
                        offset_mean[i], offset_rms[i] = field_difference(flow, terrain_flow, both)
                if (i + 1) % max(1, n // 10) == 0:
                    log(f"  {i + 1}/{n} fields")
            if rendered is not None:
                # The range meter at every pose (not only at the fields): ELOPE's, at the camera's rate.
                poses = [rendered.row_of_pose(k) for k in range(len(tr.t))]
                write_dataset(out, "range_meter/t", tr.t)
                write_dataset(out, "range_meter/slant_range_m", rendered.slant_range_m()[poses].astype(np.float32))
                write_dataset(out, "sphere_minus_terrain_mean_px_s", offset_mean)
                write_dataset(out, "sphere_minus_terrain_rms_px_s", offset_rms)
                write_dataset(out, "sphere_minus_terrain_pixels", offset_pixels)
                measured = offset_pixels > 0
                median = float(np.median(offset_rms[measured])) if measured.any() else 0.0
                attrs["sphere_minus_terrain_rms_px_s_median"] = median
                log(
                    f"sphere minus terrain-true field: median RMS {median:.3g} px/s, mean offset "
                    f"{offset_mean[measured].mean(axis=0) if measured.any() else 'none'} px/s "
                    f"({np.count_nonzero(measured)} of {n} fields see ground in both)"
                )
            set_attrs(out, attrs)
    finally:
        if rendered is not None:
            rendered.close()
