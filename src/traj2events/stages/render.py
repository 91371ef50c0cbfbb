"""Stages 4-5: render the lunar surface from every pose of a trajectory (linear radiance
and depth, frames.h5) and the videos made from the same frames (lossless FFV1 of the 8-bit
display frames, and an H.264 preview). With adaptive timing (frame_timing), frames.h5
also holds frames between the poses, at times picked from the motion field, for the
emulator only; the videos keep the fixed rate."""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator

import numpy as np

from ..formats.frames import FramesWriter
from ..formats.trajectory import read_trajectory
from ..geometry.camera import Camera
from ..geometry.frame_timing import FrameTiming, frame_motion, next_interval_s, next_render_time
from ..progress import log
from ..provenance import provenance
from ..renderer.draw import TerrainRenderer
from ..renderer.lens import LensRenderer
from ..renderer.supersample import Supersampled, sensor_renderer
from ..settings.render import RenderSettings
from ..trajectory.external import ExternalFlight
from ..trajectory.flight import SolvedFlight, flight_of
from ..trajectory.state import POSE
from ..video import VideoWriter, display_frame


def render_between(
    renderer: TerrainRenderer | LensRenderer | Supersampled,
    camera: Camera,
    states: SolvedFlight | ExternalFlight,
    frame,
    state: np.ndarray,
    t_s: float,
    t_next_s: float,
    timing: FrameTiming,
    white_w_m2_sr: float,
) -> Iterator[tuple[float, np.ndarray, object]]:
    """The adaptive frames in (t_s, t_next_s) after `frame`, rendered from `state` at t_s,
    one at a time: (t, state, frame), each interval set by the motion of the frame before
    it (frame_timing)."""
    while True:
        motion = frame_motion(frame.radiance, frame.depth_m, camera, state, white_w_m2_sr)
        t_s = next_render_time(t_s, t_next_s, next_interval_s(*motion, timing), 1.0 / timing.max_fps)
        if t_s >= t_next_s:
            return
        state = states.states([t_s])[0]
        frame = renderer.render(camera.pose(state))
        yield t_s, state, frame


class TrajectoryRender:
    """A trajectory's render job: the scene built for it (`attrs`: frames.h5's attributes),
    then its frames (`frames`)."""

    def __init__(self, trajectory: str | os.PathLike, settings: RenderSettings, tile_cache: str | None = None):
        self.trajectory, self.settings = trajectory, settings
        self.tr = tr = read_trajectory(trajectory)
        if tr.t is None or len(tr.t) < 1:
            raise ValueError(f"{trajectory}: expected poses/t with at least one pose")
        self.timing = FrameTiming(**settings.timing)
        self.camera, self.tiles, self.sun, self.reflectance = settings.build(tile_cache)
        attrs = {
            **settings.frame_attrs(self.camera, self.sun),
            "fps": float(tr.attrs["fps"]),
            "scenario": tr.attrs["scenario"],
            "id": int(tr.attrs["id"]),
            **provenance(__name__),
        }
        dem = getattr(self.tiles.terrain, "attrs", None)  # a real site's product (scene.dem), named and hashed
        dated = {"sun_utc": settings.sun["utc"]} if "utc" in settings.sun else {}  # a date drawn per trajectory
        self.attrs = {k: attrs[k] for k in FRAME_ATTR_ORDER} | (dem() if dem else {}) | dated

    def frames(
        self,
        frames: str | os.PathLike,
        video: str | os.PathLike,
        preview: str | os.PathLike | None,
        backend: str = "auto",
        keep_radiance: bool = True,
    ) -> Iterator[tuple[float, np.ndarray]]:
        """Render every pose, writing frames.h5 (radiance unless not `keep_radiance`, depth),
        video.mkv and preview.mp4 (None: none) as it goes; yields each frame's (t in s,
        radiance as frames.h5 stores it, rounded: a buffer the next frame reuses), the
        adaptive frames between poses included."""
        s, tr, tiles, camera, timing = self.settings, self.tr, self.tiles, self.camera, self.timing
        fps, n = self.attrs["fps"], len(tr.t)
        log(
            f"{self.trajectory}: rendering {n} frames of {s.width} x {s.height} (Sun az {self.sun.azimuth_deg} deg, "
            f"el {self.sun.elevation_deg} deg, {s.reflectance['model']}; {timing.mode} timing)"
        )
        # Adaptive frames need poses between the fixed ones: the same flight (re-integration, kept dense).
        states = None
        if timing.mode == "adaptive":
            states = flight_of(tr)
        start = time.perf_counter()
        triangles = reused = added = 0
        with (
            sensor_renderer(
                tiles, camera, self.sun, self.reflectance, stars=s.star_field(), backend=backend,
                earth=s.earth_light(), supersample=s.supersample,
            ) as renderer,
            FramesWriter(frames, s.height, s.width, self.attrs, keep_radiance, s.compression) as out,
            VideoWriter(video, s.width, s.height, fps, "ffv1") as lossless,
            VideoWriter(preview, s.width, s.height, fps, "h264") if preview else contextlib.nullcontext() as shown,
        ):  # fmt: skip
            log(f"  OpenGL: {renderer.backend} ({renderer.gl_renderer})")
            # A pose identical to the previous one (e.g. resting after touchdown) shows the same image.
            moved = [k == 0 or not np.array_equal(tr.state[k, POSE], tr.state[k - 1, POSE]) for k in range(n)]
            # Drawn one ahead: the GPU draws pose k+1 while this loop writes frame k.
            drawn = renderer.render_sequence(camera.pose(tr.state[k]) for k in range(n) if moved[k])
            for k in range(n):
                if moved[k]:
                    frame = next(drawn)
                    triangles += frame.n_triangles
                else:
                    reused += 1
                yield tr.t[k], out.append(tr.t[k], k, frame.radiance, frame.depth_m)
                display = display_frame(frame.radiance, s.display_white_w_m2_sr, s.display_gamma)
                lossless.write(display)
                if shown is not None:
                    shown.write(display)
                if states is not None and k + 1 < n:
                    between = render_between(
                        renderer, camera, states, frame, tr.state[k], tr.t[k], tr.t[k + 1], timing,
                        s.emulator_white_w_m2_sr,
                    )  # fmt: skip
                    for t_extra, _, extra in between:  # written as rendered: memory stays one frame
                        yield t_extra, out.append(t_extra, -1, extra.radiance, extra.depth_m)
                        triangles += extra.n_triangles
                        added += 1
                if (k + 1) % max(1, n // 10) == 0 or k + 1 == n:
                    elapsed = time.perf_counter() - start
                    log(
                        f"  {k + 1}/{n} frames (+{added} adaptive), {elapsed / (k + 1 + added) * 1e3:.1f} ms/frame, "
                        f"{tiles.n_cached} tiles cached, {triangles / max(k + 1 + added - reused, 1):.0f} "
                        "triangles/frame"
                    )
        log(
            f"{n} frames and {added} adaptive ones in {time.perf_counter() - start:.1f} s "
            f"({reused} repeated poses reused)"
        )
        log(f"tiles and shading textures: {tiles.building_s:.1f} s building them or reading them from the tile cache")
        if tiles.disk is not None:
            log(f"tiles: {tiles.n_evaluated} built, {tiles.disk.n_read} read from the tile cache {tiles.disk.folder}")
            for textures in tiles.texture_disks.values():
                log(f"shading textures: {textures.n_written} made, {textures.n_read} read from {textures.folder}")


def render_trajectory(
    trajectory: str | os.PathLike,
    settings: RenderSettings,
    frames: str | os.PathLike,
    video: str | os.PathLike,
    preview: str | os.PathLike | None,
    backend: str = "auto",
    tile_cache: str | None = None,
) -> None:
    """Render every pose of trajectory.h5: frames.h5 (radiance, depth), video.mkv and, unless
    `preview` is None, preview.mp4 (render.preview; its H.264 encoder costs CPU: docs/performance.md).
    `backend`: the OpenGL backend (renderer.context.resolve_backend); `tile_cache`: a folder where
    tile heights are shared with other jobs (formats/tile_cache.py). Neither changes the scene."""
    for _ in TrajectoryRender(trajectory, settings, tile_cache).frames(frames, video, preview, backend):
        pass


# frames.h5's attribute order (kept, so the same scene gives the same bytes).
FRAME_ATTR_ORDER = (
    "width",
    "height",
    "fov_deg",
    "focal_px",
    "fps",
    "moon_radius_m",
    "sun_range_m",
    "sun_azimuth_deg",
    "sun_elevation_deg",
    "sun_irradiance_w_m2",
    "earth",
    "reflectance",
    "terrain",
    "lod",
    "samples_per_pixel",
    "scattered_light",
    "terrain_half_extent_m",
    "display_white_w_m2_sr",
    "display_gamma",
    "timing",
    "stars",
    "scenario",
    "id",
    "traj2events_version",
    "traj2events_commit",
    "code_fingerprint",
    "camera_matrix_px",
    "distortion",
    "distortion_coefficients",
    "image_convention",
    "camera_mount_height_m",
    "camera_position",
)
