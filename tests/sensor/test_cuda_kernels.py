"""The emulator's CUDA kernels against its CPU passes, without a GPU: run under numba's CUDA
simulator (the same events and labels, byte for byte), and compiled to PTX for a real card
(types and intrinsics the simulator does not check)."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from numba import typeof

from traj2events.sensor.emulator import EventEmulator
from traj2events.stages.events import preset_params

# Run in a child process: the simulator is chosen when numba.cuda is first imported.
SIMULATED = textwrap.dedent(
    """
    import json
    from dataclasses import replace

    import numpy as np
    from numba import cuda

    from traj2events.sensor.cuda_kernels import exclusive_scan
    from traj2events.sensor.emulator import EventEmulator
    from traj2events.stages.events import preset_params

    rng = np.random.default_rng(1)
    h, w, k = 16, 16, 20
    times = np.arange(k) / 100.0
    paper = preset_params("paper")
    cases = {
        "paper, 8-bit, labels": (paper, rng.integers(0, 256, (k, h, w)).astype(np.uint8), 1.0),
        "noisy, linear input, refractory": (
            replace(paper, refractory_s=0.005, hot_pixel_fraction=0.05, hot_pixel_hz=300.0, shot_noise_hz=40.0),
            rng.uniform(0.0, 3.0, (k, h, w)).astype(np.float32),
            90.0,
        ),
        "defer, leak": (
            replace(paper, refractory_s=0.02, refractory_mode="defer", leak_hz=20.0, shot_noise_hz=0.0),
            rng.uniform(0.0, 255.0, (k, h, w)),
            1.0,
        ),
    }
    out = {}
    for name, (params, frames, scale) in cases.items():
        runs = [
            EventEmulator(w, h, params, seed=3, labels=True, input_scale=scale, device=device).process_with_labels(
                frames[:7], times[:7]
            )
            for device in ("cpu", "cuda")
        ]
        out[name] = [len(runs[0][0]), *(r[0].tobytes().hex() + r[1].tobytes().hex() for r in runs)]
    scans = []
    for n in (1, 31, 32, 33, 1500):
        values = rng.integers(0, 4, n).astype(np.int64)
        first, total = exclusive_scan(cuda.to_device(values))
        scans.append(bool(np.array_equal(first.copy_to_host(), np.cumsum(values) - values) and total == values.sum()))
    out["scans"] = scans
    print(json.dumps(out))
    """
)


@pytest.fixture(scope="module")
def simulated():
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    done = subprocess.run([sys.executable, "-c", SIMULATED], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("case", ["paper, 8-bit, labels", "noisy, linear input, refractory", "defer, leak"])
def test_the_simulated_gpu_gives_the_cpu_events_and_labels_byte_for_byte(simulated, case):
    n_events, cpu, gpu = simulated[case]
    assert n_events > 200  # signal, noise, leak and hot pixels all fire in these clips
    assert cpu == gpu


def test_the_gpu_scan_gives_exclusive_prefix_sums_across_groups(simulated):
    assert simulated["scans"] == [True] * 5


def test_an_unknown_device_is_refused_by_name():
    with pytest.raises(ValueError, match="device: expected one of"):
        EventEmulator(4, 4, preset_params("clean"), device="tpu")


@pytest.mark.parametrize("frame_dtype", [np.uint8, np.float32])
def test_the_kernels_compile_to_ptx_for_a_hopper_gpu(frame_dtype):
    """What the simulator cannot check: every call types and lowers for the GPU target
    (compute capability 9.0, H100/H200), for 8-bit and linear frames."""
    from numba import cuda

    from traj2events.sensor import cuda_kernels as ck
    from traj2events.sensor.pixel import Crossings, Events, PixelState, Thresholds

    n = 64
    frames = np.zeros(n, frame_dtype)
    f32, f64, i64, flags, labels = (np.zeros(n, d) for d in (np.float32, np.float64, np.int64, np.bool_, np.uint8))
    key = np.uint64(1)
    state, thresholds = PixelState(f64, f64, f64, f64), Thresholds(f32, f32, f32)
    crossing = Crossings(np.zeros(0, np.int64), i64, f64, f64, i64)
    noise, hot = ck.ShotNoise(f64, 5.0, 0.25, key), ck.HotPixels(flags, 0.0, key)
    kernels = {
        ck.count_kernel: (frames, frames, 1.0, 3.0, 0.01, state, thresholds, noise, hot, crossing, i64),
        ck.fill_kernel: (crossing, i64, i64, frames, 1.0, 0.01, 0.0, state, thresholds, noise, hot, 0.0, True,
                         Events(i64, f64, flags, labels)),
        ck.group_sums: (i64, i64),
        ck.group_offsets: (i64, i64, i64),
    }  # fmt: skip
    for kernel, args in kernels.items():
        ptx, _ = cuda.compile_ptx(kernel.py_func, tuple(typeof(a) for a in args), cc=(9, 0))
        assert ".entry" in ptx and "sm_90" in ptx


def test_cuda_without_a_gpu_is_refused_saying_what_to_do():
    from numba import cuda

    if cuda.is_available():
        pytest.skip("this machine has a GPU")  # the refusal is for machines without one
    with pytest.raises(RuntimeError, match="events.device: cuda: .*set events.device: cpu"):
        EventEmulator(4, 4, preset_params("clean"), device="cuda")
