"""The space environment's own events (`events.space`; off by default): particle hits and
row/column glitches, labelled `radiation` and `glitch` in events/label (docs/events.md
"Space environment").

Particle hits. Charged particles cross the sensor at `particle_flux_cm2_s` per cm^2 per s,
uniform over its area and in time (a Poisson process). An isotropic flux crosses a plane
with cos(theta) = sqrt(U), U uniform (the cosine law), at a uniform azimuth. A particle of
charge number Z frees E_PAIRS_PER_UM Z^2 electrons per um of its path through the
`sensitive_depth_um` layer (a minimum-ionising particle in silicon: ~80 per um, 3.6 eV a
pair); Z is drawn from the galactic cosmic rays' composition (GCR_SPECIES). The path,
depth / cos(theta) long, projects onto the sensor as depth tan(theta); it is walked in
steps of 1/8 pixel, and each step's charge spreads over the pixel and its neighbours as a
Gaussian of `charge_diffusion_um` (charge sharing).

A pixel's answer to a charge Q: Q arrives within nanoseconds, far faster than its
photoreceptor. A first-order photoreceptor of time constant tau carrying the current I
(photocurrent and dark current) then holds I + (Q / tau) e^(-t / tau): its log rises at once by
    Delta = ln(1 + Q / Q_ref),    Q_ref = I tau
and falls back with the tau of the pixel's own light, fast in sunlight, slow in shadow.
The bandwidth law (laws: f_c proportional to I) makes Q_ref = 13.75 I_dark / (2 pi
cutoff_hz) the same in every pixel. Events: floor(Delta / theta_on) ON events at the hit,
then an OFF event each time the log falls theta_off below the last one, while above its
level before the hit: at level L, t = tau ln((Q / Q_ref) / (e^L - 1)). A burst returns the
pixel to its reference within a threshold; it is not fed back into the emulator's state
(refractory period, leak and noise ignore it).

Row and column glitches (Falcon Neuro's "RoCo" errors on the ISS: a whole row or column
firing within a short time): at `row_column_hz` per sensor, a row or a column (even odds),
each pixel of it one event, all of one polarity (even odds), within `glitch_duration_s`.

Draws come from the seed's own generator, interval after interval, so the events are the
same however the frames are chunked. The events of an interval can fall after it (a shadowed pixel's
OFF tail lasts seconds): `SpaceEvents` holds them until the emulator's time reaches them.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special

from ..formats.events import EVENT_DTYPE, GLITCH, RADIATION
from ..settings.events import SpaceParams
from .laws import BANDWIDTH_OFFSET_DN, bandwidth_hz, bandwidth_hz_scalar

ELEMENTARY_CHARGE_C = 1.602176634e-19
E_PAIRS_PER_UM = 80.0  # a minimum-ionising particle in silicon (most probable loss ~0.29 keV/um, 3.6 eV a pair)
# Galactic cosmic rays by number: ~87 % protons, ~12 % helium, ~1 % heavier nuclei (Simpson
# 1983); the heavier split as C-N-O (taken as oxygen) and the iron group, 9 : 1 (assumed).
GCR_SPECIES = ((1, 0.87), (2, 0.12), (8, 0.009), (26, 0.001))
STEPS_PER_PIXEL = 8  # the track's walk
SPACE_STREAM = 0x5A0E  # the draws' own stream of the seed
# `SpaceEvents.due` with nothing pending (most intervals): no events, and no work.
NOTHING_DUE = {**{k: np.empty(0, EVENT_DTYPE[k]) for k in EVENT_DTYPE.names}, "label": np.empty(0, np.uint8)}


# The space environment off, as events.h5 records it: no particles, no glitches.
NO_SPACE = SpaceParams(enabled=False, particle_flux_cm2_s=0.0, row_column_hz=0.0)


def burst_levels(charge_ratio: float, theta_on: float, theta_off: float) -> tuple[int, np.ndarray]:
    """A hit of Q = charge_ratio Q_ref on a pixel: (ON events at the hit, the log levels of
    its OFF events as it recovers, highest first)."""
    n_on = int(math.floor(math.log1p(charge_ratio) / theta_on))
    top = n_on * theta_on
    n_off = max(int(math.ceil(top / theta_off)) - 1, 0)  # levels strictly above the pixel's own
    return n_on, top - theta_off * np.arange(1, n_off + 1)


def recovery_times_s(charge_ratio: float, levels: np.ndarray, tau_s: float) -> np.ndarray:
    """When the pixel's log falls back to each level: ln(1 + r e^(-t / tau)) = L; within
    4 eps (tau + t) (docs/accuracy.md)."""
    return tau_s * np.log(charge_ratio / np.expm1(levels))


def reference_charge_c(intensity_dn: np.ndarray, dark_current_a: float, cutoff_hz: float) -> np.ndarray:
    """Q_ref = I tau of pixels at `intensity_dn` (the emulator's sensor units: 20 DN is one
    dark current, the bandwidth law's offset the dark current itself)."""
    intensity_dn = np.asarray(intensity_dn, dtype=np.float64)
    current_a = (intensity_dn + BANDWIDTH_OFFSET_DN) * dark_current_a / BANDWIDTH_OFFSET_DN
    return current_a / (2 * np.pi * bandwidth_hz(intensity_dn, cutoff_hz))


def draw_hits(rng: np.random.Generator, flux_cm2_s: float, width: int, height: int, pitch_m: float, dt_s: float):
    """One interval's hits: (times since its start s, x, y in pixels, cos theta, azimuth, Z)."""
    area_cm2 = width * height * (pitch_m * 100.0) ** 2
    n = rng.poisson(flux_cm2_s * area_cm2 * dt_s)
    if not n:
        return (np.empty(0),) * 6
    t = rng.uniform(0.0, dt_s, n)
    x, y = rng.uniform(0.0, width, n), rng.uniform(0.0, height, n)
    cos_theta = np.sqrt(rng.uniform(0.0, 1.0, n))
    azimuth = rng.uniform(0.0, 2 * np.pi, n)
    z, share = np.array([s[0] for s in GCR_SPECIES]), np.array([s[1] for s in GCR_SPECIES])
    charge_number = z[rng.choice(len(z), n, p=share / share.sum())]
    return t, x, y, cos_theta, azimuth, charge_number


def track_charges(
    x: float, y: float, cos_theta: float, azimuth: float, charge_number: int, params: SpaceParams, pitch_um: float,
    width: int, height: int,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(pixels (index y W + x), electrons each collects) of one particle's track."""
    depth = params.sensitive_depth_um
    total_e = E_PAIRS_PER_UM * charge_number**2 * depth / max(cos_theta, 1e-3)
    length_px = min(depth * math.sqrt(max(1.0 - cos_theta**2, 0.0)) / max(cos_theta, 1e-3) / pitch_um,
                    float(max(width, height)))  # fmt: skip
    steps = max(int(math.ceil(length_px * STEPS_PER_PIXEL)), 1)
    along = (np.arange(steps) + 0.5) / steps * length_px
    xs, ys = x + along * math.cos(azimuth), y + along * math.sin(azimuth)
    sigma_px = params.charge_diffusion_um / pitch_um
    offsets = np.arange(-math.ceil(4 * sigma_px), math.ceil(4 * sigma_px) + 1)
    cols, rows = np.floor(xs)[:, None] + offsets, np.floor(ys)[:, None] + offsets  # (steps, cells)
    share = cell_shares(ys[:, None], rows, sigma_px)[:, :, None] * cell_shares(xs[:, None], cols, sigma_px)[:, None]
    inside = ((rows >= 0) & (rows < height))[:, :, None] & ((cols >= 0) & (cols < width))[:, None, :]
    keep = inside & (share > 1e-9)
    pixels = (rows[:, :, None] * width + cols[:, None, :])[keep].astype(np.int64)
    unique, slot = np.unique(pixels, return_inverse=True)
    return unique, np.bincount(slot, weights=share[keep]) * (total_e / steps)


def cell_shares(centre, cells: np.ndarray, sigma: float) -> np.ndarray:
    """A Gaussian's share in each unit cell [c, c + 1) along one axis: within 2 eps absolute
    (the difference of two erfs; docs/accuracy.md)."""
    scale = sigma * math.sqrt(2.0)
    return 0.5 * (special.erf((cells + 1 - centre) / scale) - special.erf((cells - centre) / scale))


class SpaceEvents:
    """The space environment's events of one recording, interval by interval: `interval`
    returns those due by the interval's end (sorted by t), `due` those due by a time."""

    def __init__(
        self, params: SpaceParams, width: int, height: int, pixel_pitch_m: float, dark_current_a: float,
        cutoff_hz: float, seed: int,
    ) -> None:  # fmt: skip
        if params.particle_flux_cm2_s > 0 and not cutoff_hz > 0:
            raise ValueError("events.space: particle hits need events.pixel.cutoff_hz > 0 (the photoreceptor's "
                             "bandwidth sets a pixel's answer to a hit)")  # fmt: skip
        self.params, self.width, self.height = params, width, height
        self.pitch_m, self.dark_current_a, self.cutoff_hz = pixel_pitch_m, dark_current_a, cutoff_hz
        self._rng = np.random.Generator(np.random.PCG64([seed, SPACE_STREAM]))  # drawn interval by interval
        self._pending = _columns(np.empty(0, np.int64), np.empty(0, np.int64), np.empty(0, bool), np.empty(0, np.uint8))
        self.hits = 0
        self.glitches = 0

    def interval(
        self, t0_s: float, t1_s: float, frame: np.ndarray, input_scale: float, theta_on: np.ndarray,
        theta_off: np.ndarray,
    ) -> dict[str, np.ndarray]:  # fmt: skip
        """The interval's hits and glitches (`frame`: the pixels' input at its end, flat, times
        `input_scale` the emulator's sensor units; the pixels' thresholds); the events due by
        t1 (pending ones included)."""
        rng, dt = self._rng, t1_s - t0_s
        pix, t_s, on, label = [], [], [], []
        p = self.params
        if p.particle_flux_cm2_s > 0:
            for hit in zip(*draw_hits(rng, p.particle_flux_cm2_s, self.width, self.height, self.pitch_m, dt)):
                self.hits += 1
                self._burst(t0_s + hit[0], hit[1:], (frame, input_scale), (theta_on, theta_off), pix, t_s, on, label)
        if p.row_column_hz > 0:
            for _ in range(rng.poisson(p.row_column_hz * dt)):
                self.glitches += 1
                is_row, polarity, start = rng.uniform() < 0.5, rng.uniform() < 0.5, t0_s + rng.uniform(0.0, dt)
                line = int(rng.integers(self.height if is_row else self.width))
                n = self.width if is_row else self.height
                cells = np.arange(n)
                pix.append(line * self.width + cells if is_row else cells * self.width + line)
                t_s.append(start + rng.uniform(0.0, p.glitch_duration_s, n))
                on.append(np.full(n, polarity))
                label.append(np.full(n, GLITCH, np.uint8))
        if pix:
            new = _columns(np.concatenate(pix), np.round(np.concatenate(t_s) * 1e6).astype(np.int64),
                           np.concatenate(on), np.concatenate(label))  # fmt: skip
            self._pending = {k: np.concatenate([self._pending[k], new[k]]) for k in new}
        return self.due(int(round(t1_s * 1e6)))

    def _burst(self, t_hit_s, hit, intensity, thresholds, pix, t_s, on, label) -> None:
        x, y, cos_theta, azimuth, z = hit
        pixels, charges = track_charges(x, y, cos_theta, azimuth, int(z), self.params, self.pitch_m * 1e6,
                                        self.width, self.height)  # fmt: skip
        x_dn = intensity[0][pixels].astype(np.float64) * intensity[1]
        ratios = charges * ELEMENTARY_CHARGE_C / reference_charge_c(x_dn, self.dark_current_a, self.cutoff_hz)
        theta_on, theta_off = thresholds[0][pixels], thresholds[1][pixels]
        fires = np.log1p(ratios) >= theta_on  # at least one ON event: the others are left at once
        for i, x_i, ratio, on_i, off_i in zip(pixels[fires], x_dn[fires], ratios[fires], theta_on[fires],
                                              theta_off[fires]):  # fmt: skip
            n_on, levels = burst_levels(float(ratio), float(on_i), float(off_i))
            tau_s = 1.0 / (2 * np.pi * bandwidth_hz_scalar(float(x_i), self.cutoff_hz))
            times = np.concatenate([np.zeros(n_on), recovery_times_s(float(ratio), levels, tau_s)])
            pix.append(np.full(len(times), i))
            t_s.append(t_hit_s + times)
            on.append(np.arange(len(times)) < n_on)
            label.append(np.full(len(times), RADIATION, np.uint8))

    def due(self, t_us: int) -> dict[str, np.ndarray]:
        """The pending events at or before t_us as x, y, t, p, label columns, sorted by
        (t, y, x, p); the rest stay pending."""
        if not len(self._pending["t"]):
            return NOTHING_DUE
        now = self._pending["t"] <= t_us
        out = {k: v[now] for k, v in self._pending.items()}
        self._pending = {k: v[~now] for k, v in self._pending.items()}
        y, x = np.divmod(out["pix"], self.width)
        order = np.lexsort((out["p"], x, y, out["t"]))
        columns = {"x": x, "y": y, "t": out["t"], "p": out["p"]}
        return {**{k: v[order].astype(EVENT_DTYPE[k]) for k, v in columns.items()}, "label": out["label"][order]}


def _columns(pix: np.ndarray, t_us: np.ndarray, on: np.ndarray, label: np.ndarray) -> dict[str, np.ndarray]:
    return {"pix": pix.astype(np.int64), "t": t_us, "p": on.astype(np.uint8), "label": label}
