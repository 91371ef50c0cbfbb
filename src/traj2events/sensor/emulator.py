"""Event-camera emulator: frames -> events (docs/events.md: the model and its checks).

Each pixel keeps a low-passed log intensity, a reference `base` and its last event time.
Per frame interval [t_k, t_k+1]:
  1. log response L(I): linear below the 20 DN knee, ln above            (laws)
  2. first-order low-pass, bandwidth growing with I, solved exactly       (laws, pixel.advance)
  3. per-pixel thresholds N(theta, sigma) clipped at 0.01, drawn once      (__init__)
  4. an event wherever the filtered L, linear within the interval, crosses
     base + theta_on or base - theta_off, timed where its own pixel crosses
     (ESIM); base moves by one threshold per crossing                      (pixel.advance, pixel.emit)
  5. refractory period: a crossing closer than T_ref to the pixel's last
     event is dropped and base still moves ("drop", ESIM), or stays pending
     and fires at the first frame after the period ("defer", v2e)          (laws, pixel.emit)
  6. leak: base drifts down by theta_on per leak period (rate
     R_leak 10^(0.1 N(0, 1)) per pixel, from a random phase)               (pixel.advance)
  7. shot noise: Poisson ON/OFF events at R_shot g(I) theta_nom / theta(x);
     a noise event resets the pixel's reference to its current signal       (noise, pixel.emit)
  8. hot pixels: a fraction of pixels firing ON at a fixed rate            (noise, pixel.emit)

Events are a numpy structured array (x, y, t, p) in tonic's convention: x column, y row
(uint16), t int64 microseconds (rounded), p 1 = ON, 0 = OFF, sorted by t (or, from
`intervals(columns=True)`, a dict of those four columns). On request (`labels=True`) each
event also gets its cause (`formats.events.EVENT_LABELS`): signal, shot noise, leak or hot
pixel; the labels never change the events. Streaming: `EventEmulator.process` takes any
number of frames at a time and keeps only per-pixel state, and every random draw is keyed
by (seed, frame interval, pixel) (`draws`), so the output is the same bytes however the
video is chunked and whichever thread or device does a pixel.
Input: 8-bit DN, or float DN-equivalents of linear radiance (radiance times `input_scale`,
applied per pixel in float64 inside the kernels).

Read this module, `pixel` (the per-pixel loop), `noise` and `laws`; the machinery behind them is
`draws` (random numbers keyed by what they are for), `ordering` (sorting each interval's
events) and `parallel` (the per-pixel pass split over threads).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..formats.events import EVENT_DTYPE
from ..settings.events import EmulatorParams
from .draws import HOT_PIXEL_STREAM, SHOT_NOISE_STREAM, interval_key
from .laws import log_intensity_8bit, lowpass_gain
from .noise import block_majorants, shot_noise_events
from .ordering import assemble
from .parallel import RangedPass, pixel_ranges
from .pixel import Crossings, Events, PixelState, Thresholds, advance, emit, hot_pixel_counts


def _rng(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, *key]))


_LOG_LUT_8BIT = log_intensity_8bit(np.arange(256.0))  # every value 8-bit input can take
_NO_TABLE = np.empty(0)
_NO_PIXELS = np.empty(0, np.int64)
DEVICES = ("cpu", "cuda")


def device_problem(device: str) -> str | None:
    """Why `device` cannot run the pixel model on this machine (None: it can): the
    workflow asks before any job, a cluster's login node aside (its GPU jobs run elsewhere)."""
    if device != "cuda":
        return None
    try:
        from numba import cuda

        if cuda.is_available():
            return None
    except ImportError:
        pass
    return ("events.device: cuda: numba finds no usable NVIDIA GPU here (a driver, and `pip install "
            "traj2events[gpu]` for numba-cuda); set events.device: cpu to emulate on the CPUs")  # fmt: skip


class EventEmulator:
    """Streaming emulator for frames of a fixed size; see the module docstring."""

    def __init__(
        self,
        width: int,
        height: int,
        params: EmulatorParams,
        seed: int = 0,
        labels: bool = False,
        input_scale: float = 1.0,
        threads: int = 1,
        device: str = "cpu",
    ) -> None:
        """`labels`: also label each event with its cause (`process_with_labels`).
        `input_scale`: the frames times this are the model's DN (e.g. radiance times
        `sensor.photocurrent.dn_per_radiance`), applied per pixel in float64, so float32 frames need
        no float64 copy; 8-bit frames with a scale of 1 use tables. `threads`: the per-pixel
        pass split over up to this many threads (rows of at least PIXELS_PER_THREAD pixels
        each); the same events however many. `device`: "cpu", or "cuda" for the pixel model
        on the GPU (`cuda_kernels`: the same events, but where the GPU's math library
        rounds a crossing differently)."""
        if device not in DEVICES:
            raise ValueError(f"EventEmulator: device: expected one of {DEVICES}, got {device!r}")
        if not (input_scale > 0 and np.isfinite(input_scale)):
            raise ValueError(f"EventEmulator: input_scale: expected a finite value > 0, got {input_scale}")
        if not (isinstance(threads, int) and threads >= 1):
            raise ValueError(f"EventEmulator: threads: expected an integer >= 1, got {threads!r}")
        self.width, self.height, self.params, self.seed, self.labels = width, height, params, seed, labels
        self.input_scale = float(input_scale)
        n = width * height
        rng = _rng(seed, 0)
        self.theta_on = (
            np.maximum(rng.normal(params.theta_on, params.sigma, n), 0.01)
            if params.sigma
            else np.full(n, params.theta_on)
        )
        self.theta_off = (
            np.maximum(rng.normal(params.theta_off, params.sigma, n), 0.01)
            if params.sigma
            else np.full(n, params.theta_off)
        )
        self.leak_rate = params.leak_hz * 10.0 ** (0.1 * rng.standard_normal(n)) if params.leak_hz else np.zeros(n)
        self.leak_phase = rng.uniform(0.0, 1.0, n)
        hot = rng.uniform(size=n) < params.hot_pixel_fraction
        self.hot_pixels = np.flatnonzero(hot)
        self._intensity: np.ndarray | None = None  # input (DN) at the last frame
        self._state: PixelState | None = None  # set at the first frame
        self._last_event = np.full(n, -np.inf)  # s
        # Base's drift per second, and the thresholds, in float32: less for the per-frame
        # pass to read, and these are random draws whose last bits carry nothing.
        self._leak_step = (self.theta_on * self.leak_rate).astype(np.float32)
        self.theta_on, self.theta_off = self.theta_on.astype(np.float32), self.theta_off.astype(np.float32)
        self._thresholds = Thresholds(self.theta_on, self.theta_off, self._leak_step)
        self._noise_majorants = block_majorants(self.theta_on, self.theta_off, params.theta_on)  # thinning (7.)
        # Work arrays of the compiled kernels, reused every frame.
        self._crossings = Crossings(*(np.zeros(n, d) for d in (np.int64, np.int64, np.float64, np.float64, np.int64)))
        self._noise = (np.zeros(0, np.int64), np.zeros(0), np.zeros(0, np.bool_))  # grown as needed
        self._ranged_pass = RangedPass(pixel_ranges(n, threads))
        self._gpu = None
        if device == "cuda":
            if problem := device_problem(device):
                raise RuntimeError(problem)
            from .cuda_kernels import CudaPixels  # numba.cuda only where asked for

            self._gpu = CudaPixels(
                self.theta_on, self.theta_off, self._leak_step, self._noise_majorants, self.hot_pixels, self.labels
            )
        self._t: float | None = None
        self._interval = 0  # index of the next frame interval (keys the random draws)

    def process(self, frames_dn: np.ndarray, times_s: np.ndarray) -> np.ndarray:
        """Feed frames (K, H, W) in DN (8-bit values, or float DN-equivalents, e.g. from
        `radiance_to_dn`), times `input_scale`, with their times (K,) in s; events up to
        the last one."""
        return self._joined(self.intervals(frames_dn, times_s))[0]

    def process_with_labels(self, frames_dn: np.ndarray, times_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As `process`, and each event's label (uint8, `formats.events.EVENT_LABELS`): the
        same events, byte for byte. Needs `labels=True` from the start."""
        if not self.labels:
            raise ValueError("EventEmulator: labels need labels=True when the emulator is made")
        return self._joined(self.intervals(frames_dn, times_s))

    def intervals(
        self, frames_dn: np.ndarray, times_s: np.ndarray, columns: bool = False
    ) -> Iterator[tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]]:
        """As `process` (with labels: `process_with_labels`), one frame interval's events
        (and labels, else None) at a time: the same events, with memory for one interval's
        events instead of the chunk's (a writer can take each as it comes). `columns`: each
        interval's events as a dict of contiguous x, y, t, p arrays instead of a structured
        array (the same values; EventsWriter takes either, columns without splitting records)."""
        frames = np.asarray(frames_dn)
        times = np.asarray(times_s, dtype=np.float64)
        if frames.ndim != 3 or frames.shape[1:] != (self.height, self.width) or len(times) != len(frames):
            raise ValueError(
                f"frames: expected (K, {self.height}, {self.width}) with K timestamps, "
                f"got {frames.shape} and {times.shape}"
            )
        # min and max propagate NaN: two passes, no temporary arrays.
        if frames.dtype.kind == "f" and frames.size and not (frames.min() >= 0 and frames.max() < np.inf):
            bad = int(
                np.argmax(
                    ~np.isfinite(frames).reshape(len(frames), -1).all(axis=1)
                    | (frames.reshape(len(frames), -1).min(axis=1) < 0)
                )
            )
            raise ValueError(
                f"frames: expected finite values >= 0 (intensity), frame {bad} of this chunk "
                f"(t = {times[bad]:.6f} s) has NaN, inf or negative values"
            )
        if frames.dtype == np.uint8 and self.input_scale != 1.0:
            frames = frames.astype(np.float32)  # scaled 8-bit: no tables (exact in float32)
        elif frames.dtype.kind != "f" and frames.dtype != np.uint8:
            frames = frames.astype(np.float64)
        for frame, t in zip(frames, times):
            # 8-bit frames stay 8-bit (the kernel reads tables); float frames are read as
            # they are (float32 or float64) and scaled in the kernels.
            intensity = frame.reshape(-1)
            if self._t is None:
                self._start(intensity, float(t))
                continue
            if not t > self._t:
                raise ValueError(f"timestamps: expected strictly increasing, got {t} after {self._t}")
            yield self._interval_events(intensity, float(t), columns)
        if self._intensity is not None and self._intensity.base is not None:
            self._intensity = self._intensity.copy()  # kept for the next call: not a view of this chunk

    def _joined(
        self, intervals: Iterator[tuple[np.ndarray, np.ndarray | None]]
    ) -> tuple[np.ndarray, np.ndarray | None]:
        chunks = list(intervals)
        # Joined as bytes: NumPy copies the 13-byte packed records one by one, bytes in bulk (3-4x).
        events = (
            np.concatenate([c[0].view(np.uint8) for c in chunks]).view(EVENT_DTYPE)
            if chunks
            else np.empty(0, EVENT_DTYPE)
        )
        if not self.labels:
            return events, None
        return events, np.concatenate([c[1] for c in chunks]) if chunks else np.empty(0, np.uint8)

    def _start(self, intensity: np.ndarray, t: float) -> None:
        log_i = log_intensity_8bit(np.asarray(intensity, dtype=np.float64) * self.input_scale)
        self._intensity, self._t = intensity, t
        # Random leak phase: base starts a random fraction of theta_on below the signal.
        phase_drift = self.leak_phase * self.theta_on * (self.leak_rate > 0)
        # With labels, that offset is leak drift, pending from the start.
        leak_drift = phase_drift.astype(np.float64) if self.labels else _NO_TABLE
        self._state = PixelState(log_i.copy(), log_i - phase_drift, leak_drift, self._last_event)
        if self._gpu is not None:
            self._gpu.start(intensity, self._state)

    def _advance_ranges(self, intensity0, intensity1, dt, log_lut, gain_lut) -> int:
        """`pixel.advance` over every pixel, a range of pixels per thread; returns how many
        pixels cross, listed in pixel order in the slots."""
        state, thresholds, slots = self._state, self._thresholds, self._crossings
        cutoff_hz = float(self.params.cutoff_hz)

        def advance_range(start: int, stop: int) -> int:
            r = slice(start, stop)  # (an empty leak_drift, no labels, stays empty)
            return advance(intensity0[r], intensity1[r], PixelState(*(a[r] for a in state)),
                           Thresholds(*(a[r] for a in thresholds)), cutoff_hz, dt, self.input_scale, log_lut,
                           gain_lut, start, Crossings(*(a[r] for a in slots)))  # fmt: skip

        return self._ranged_pass(advance_range, slots)

    def _interval_events(
        self, intensity: np.ndarray, t1: float, columns: bool = False
    ) -> tuple[np.ndarray | dict[str, np.ndarray], np.ndarray | None]:
        p = self.params
        t0, dt = self._t, t1 - self._t
        # x = signal - base, linear in t within the interval: low-pass (exact, bandwidth from
        # the interval's mean input), log, the leak's drift of base, crossings; and the noise.
        if intensity.dtype != self._intensity.dtype:  # 8-bit and float frames mixed: all float
            intensity, self._intensity = intensity.astype(np.float64), self._intensity.astype(np.float64)
        if intensity.dtype == np.uint8:
            log_lut = _LOG_LUT_8BIT
            gain_lut = lowpass_gain(0.5 * np.arange(511.0), p.cutoff_hz, dt)  # by I0 + I1
        else:
            log_lut = gain_lut = _NO_TABLE
        if self._gpu is not None:
            pix, t, on, label = self._gpu.interval(
                intensity, self.input_scale, dt, t0, p, interval_key(self.seed, SHOT_NOISE_STREAM, self._interval),
                interval_key(self.seed, HOT_PIXEL_STREAM, self._interval),
            )  # fmt: skip
            self._intensity, self._t = intensity, t1
            self._interval += 1
            return assemble(pix, t, on, label if self.labels else None, self.width, self.width * self.height, columns)
        n_active = self._advance_ranges(self._intensity, intensity, dt, log_lut, gain_lut)
        noise_pix, noise_s, noise_on, n_noise = self._shot_noise(intensity, dt)
        hot_key = interval_key(self.seed, HOT_PIXEL_STREAM, self._interval)
        hot_pixels = self.hot_pixels if p.hot_pixel_hz > 0 else _NO_PIXELS
        hot_counts = hot_pixel_counts(hot_pixels, hot_key, float(p.hot_pixel_hz), dt)
        n_room = int(np.abs(self._crossings.count[:n_active]).sum()) + n_noise + int(hot_counts.sum())
        out = Events(*(np.empty(n_room, d) for d in (np.int64, np.float64, np.bool_, np.uint8)))
        k = emit(self._crossings, n_active, (noise_pix, noise_s, noise_on), n_noise, hot_pixels, hot_counts, hot_key,
                 float(p.hot_pixel_hz), self._thresholds, self._state, t0, dt, float(p.refractory_s),
                 p.refractory_mode == "defer", out)  # fmt: skip
        pix, t, on, label = out
        self._intensity, self._t = intensity, t1
        self._interval += 1
        n_pixels = self.width * self.height
        return assemble(pix[:k], t[:k], on[:k], label[:k] if self.labels else None, self.width, n_pixels, columns)

    def _shot_noise(self, intensity: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """7. The interval's shot noise, (pixel, time since the interval's start, ON) in pixel
        order, and how many (`noise.shot_noise_events`)."""
        p = self.params
        if p.shot_noise_hz <= 0:
            return (*self._noise, 0)
        args = (
            intensity,
            self.input_scale,
            self.theta_on,
            self.theta_off,
            float(p.theta_on),
            self._noise_majorants,
            float(p.shot_noise_hz),
            interval_key(self.seed, SHOT_NOISE_STREAM, self._interval),
            dt,
        )
        n = shot_noise_events(*args, *self._noise)
        if n > len(self._noise[0]):  # more than the room: again, with room to spare
            room = 2 * n
            self._noise = (np.empty(room, np.int64), np.empty(room), np.empty(room, np.bool_))
            n = shot_noise_events(*args, *self._noise)
        return (*self._noise, n)
