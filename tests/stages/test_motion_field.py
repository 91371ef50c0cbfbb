"""motion_field.h5 (stages/motion_field.py) driven by configs the check accepts: the camera,
its lens and the motion field's keys drawn across their declared bounds, over poses
anywhere a flight can be (docs/accuracy.md "End-to-end stress")."""

from pathlib import Path

import h5py
import hdf5plugin  # noqa: F401  (motion_field.h5 is Blosc-compressed)
import numpy as np
from hypothesis import assume, event, example, given, settings
from hypothesis import strategies as st

from declared_values import declared_values
from traj2events.config import ConfigError, resolve_config
from traj2events.formats.flow import read_flo
from traj2events.formats.frames import FramesWriter
from traj2events.formats.trajectory import write_trajectory
from traj2events.geometry.camera import Camera
from traj2events.geometry.motion_field import SKY, VISIBLE, depth_flow
from traj2events.settings.camera import CameraSection, LensDistortion, MotionFieldSection, motion_field_settings
from traj2events.stages.motion_field import motion_field

N_POSES = 3
LONGEST_FLIGHT_S = 3600.0  # an hour's hover, the longest the check accepts
LENS_CAPS = dict.fromkeys(("k1", "k2", "p1", "p2", "k3"), 2.0)  # within +-2 (the check refuses larger ones: folds)


def pose_states() -> st.SearchStrategy[np.ndarray]:
    """(N_POSES, 13) states anywhere a landing goes: 1 m to 100 km up, within 200 km of the
    site, any roll and yaw, pitch within 89.9 deg, speeds to 1680 m/s and rates to 1 rad/s
    per axis, each pose its own (the stage takes them as given)."""
    one = st.tuples(
        st.floats(-2e5, 2e5), st.floats(-2e5, 2e5), st.floats(1.0, 1e5),
        *[st.floats(-1680.0, 1680.0)] * 3,
        st.floats(-np.pi, np.pi), st.floats(-np.radians(89.9), np.radians(89.9)), st.floats(-np.pi, np.pi),
        *[st.floats(-1.0, 1.0)] * 3,
    )  # fmt: skip
    return st.lists(one, min_size=N_POSES, max_size=N_POSES).map(_states)


def _states(rows) -> np.ndarray:
    state = np.array([[*r, 1000.0] for r in rows])
    state[:, 2] *= -1.0  # z down: altitude up
    return state


def sphere_depth(camera: Camera, state: np.ndarray, radius_m: float) -> np.ndarray:
    """(H, W) depth along the boresight where each pixel's ray, in float64, meets the sphere
    (the site `radius_m` above its centre); 0 where it misses."""
    pose = camera.pose(state)
    x_s, y_s = np.broadcast_arrays(*camera.pixel_coordinates())
    rays = camera.back_project(x_s, y_s) @ pose.rotation.T  # to one metre of depth
    from_centre = pose.position - [0.0, 0.0, radius_m]
    a = np.einsum("...i,...i", rays, rays)
    half_b = rays @ from_centre
    discriminant = half_b**2 - a * (from_centre @ from_centre - radius_m**2)
    with np.errstate(invalid="ignore"):
        depth = (-half_b - np.sqrt(discriminant)) / a  # the near root
    return np.where((discriminant > 0) & (depth > 0), depth, 0.0)


def write_inputs(folder: Path, camera: Camera, radius_m: float, fps: float, state: np.ndarray) -> None:
    t = np.arange(N_POSES) / fps
    attrs = {"fps": fps, "scenario": "descent", "id": 0, "tf_s": t[-1]}
    write_trajectory(folder / "trajectory.h5", (t, state, np.zeros((N_POSES, 4))),
                     (t, state, np.zeros((N_POSES, 4))), attrs, camera.mount_height_m)  # fmt: skip
    scene = {"width": camera.width, "height": camera.height, "fov_deg": camera.fov_deg, "focal_px": camera.focal_px,
             "moon_radius_m": radius_m, **camera.intrinsics_attrs()}  # fmt: skip
    with FramesWriter(folder / "frames.h5", camera.height, camera.width, scene) as frames:
        for k in range(N_POSES):
            depth = sphere_depth(camera, state[k], radius_m)
            frames.append(t[k], k, np.ones_like(depth, np.float32), depth)


@settings(max_examples=max(settings.default.max_examples // 10, 10), deadline=None)
# the search's find: the middle pose rolled 115 deg sees only sky, and its sphere-minus-terrain mean was NaN
@example({"fps": 1.0, "width": 1, "height": 1, "fov_deg": 1.0, "mount_height_m": 0.0}, dict.fromkeys(LENS_CAPS, 0.0),
         {"every_n_frames": 1, "moon_radius_m": 1.7e6}, _states([(0, 0, 1, *[0] * 9), (0, 0, 1, 0, 0, 0, 2.0, *[0] * 5),
                                                                  (0, 0, 1, *[0] * 9)]))  # fmt: skip
@given(
    declared_values(CameraSection, width=8, height=8), declared_values(LensDistortion, **LENS_CAPS),
    declared_values(MotionFieldSection, every_n_frames=2), pose_states(),
)  # fmt: skip
def test_no_camera_or_motion_field_the_check_accepts_writes_a_nan_or_an_inf(
    tmp_path_factory, camera, distortion, field, state
):
    """Issue 71: for each camera, lens and motion field the check accepts and poses
    anywhere a flight can be, every value of motion_field.h5 and the .flo files is finite,
    and where the rendered depth is the sphere's (16 significant bits) and both fields see
    the sphere, the terrain-true flow is the sphere's within that rounding of its
    translation part."""
    try:
        config = resolve_config({"camera": {**camera, "distortion": distortion}, "motion_field": field})
    except ConfigError as error:
        event(f"refused: {str(error).split(':')[0]}")
        return
    assume(1.0 / config["camera"]["fps"] <= LONGEST_FLIGHT_S / (N_POSES - 1))
    s = motion_field_settings(config)
    model, radius_m = Camera.from_settings(s), s["moon_radius_m"]
    folder = tmp_path_factory.mktemp("field")
    write_inputs(folder, model, radius_m, config["camera"]["fps"], state)
    motion_field(folder / "trajectory.h5", model, radius_m, s["every_n_frames"], folder / "mf.h5", folder / "flow",
                 folder / "frames.h5")  # fmt: skip
    with h5py.File(folder / "mf.h5") as f:
        for name, data in _datasets(f):
            if data.dtype.kind == "f":
                assert np.isfinite(data).all(), name
        for i, k in enumerate(f["frame_index"][()]):
            assert np.isfinite(read_flo(folder / "flow" / f"{k:06d}.flo")).all()
            sphere, terrain = f["flow_sphere"][i].astype(float), f["flow_terrain"][i].astype(float)
            rotation, _ = depth_flow(model, state[k], np.zeros((model.height, model.width)))  # points at infinity
            both = (f["status_sphere"][i] != SKY) & (f["status_terrain"][i] != SKY)
            assert f["sphere_minus_terrain_pixels"][i] == np.count_nonzero(both)
            rounding = 2.0**-15 * np.abs(sphere - rotation) + 1e-5 * np.abs(sphere) + 1e-30
            assert np.all(np.abs(terrain - sphere)[both] <= rounding[both]), (terrain[both], sphere[both])
            assert np.all(f["status_terrain"][i][f["status_sphere"][i] == VISIBLE] != SKY)


def _datasets(group, prefix=""):
    for name, item in group.items():
        if isinstance(item, h5py.Group):
            yield from _datasets(item, f"{prefix}{name}/")
        else:
            yield prefix + name, item[()]
