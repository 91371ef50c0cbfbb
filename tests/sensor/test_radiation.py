"""The space environment's events (sensor.radiation) against their laws: the hit rate per
area and time, the cosine law, the charge a track frees, a pixel's burst worked by hand,
the glitches' lines, and the stream's order and independence from chunking."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from normal_floats import normal_floats
from traj2events.formats.events import GLITCH, RADIATION
from traj2events.sensor.radiation import (
    E_PAIRS_PER_UM,
    GCR_SPECIES,
    SpaceEvents,
    SpaceParams,
    burst_levels,
    cell_shares,
    draw_hits,
    recovery_times_s,
    reference_charge_c,
    track_charges,
)

PITCH_M = 4.86e-6
DARK_A = 1e-15


def test_hits_per_area_and_time_follow_the_flux():
    rng = np.random.default_rng(1)
    flux, width, height, dt, intervals = 50.0, 200, 100, 0.02, 2000
    counts = [len(draw_hits(rng, flux, width, height, PITCH_M, dt)[0]) for _ in range(intervals)]
    expected = flux * width * height * (PITCH_M * 100) ** 2 * dt * intervals  # hits
    assert abs(sum(counts) - expected) < 4 * math.sqrt(expected)
    assert np.var(counts) == pytest.approx(np.mean(counts), rel=0.15)  # Poisson: variance = mean


def test_directions_follow_the_cosine_law_and_species_the_composition():
    rng = np.random.default_rng(2)
    t, x, y, cos_theta, azimuth, z = draw_hits(rng, 1e7, 100, 100, PITCH_M, 1.0)
    n = len(cos_theta)
    assert np.mean(cos_theta) == pytest.approx(2 / 3, abs=4 * math.sqrt(1 / 18 / n))  # p(c) = 2c: mean 2/3
    assert np.mean(cos_theta**2) == pytest.approx(1 / 2, abs=0.01)
    assert np.mean(z == 1) == pytest.approx(GCR_SPECIES[0][1], abs=4 * math.sqrt(0.87 * 0.13 / n))
    assert (t >= 0).all() and (t < 1).all() and (x < 100).all() and np.abs(np.mean(azimuth) - np.pi) < 0.05


@pytest.mark.parametrize("cos_theta, z", [(1.0, 1), (0.5, 2), (0.2, 1)])
def test_a_track_frees_80_electrons_per_um_times_z_squared(cos_theta, z):
    params = SpaceParams(enabled=True, sensitive_depth_um=5.0, charge_diffusion_um=1.0)
    pixels, charges = track_charges(40.2, 30.7, cos_theta, 0.3, z, params, PITCH_M * 1e6, 100, 100)
    total = charges.sum()
    assert total == pytest.approx(E_PAIRS_PER_UM * z**2 * 5.0 / cos_theta, rel=1e-3)
    # the track's projection, depth tan(theta), and the charge cloud's reach set its pixels
    reach_px = 5.0 * math.sqrt(1 - cos_theta**2) / cos_theta / 4.86
    columns = sorted(set((pixels % 100).tolist()))
    assert columns[-1] - columns[0] <= math.ceil(reach_px) + 2


def test_a_vertical_track_shares_its_charge_as_the_diffusion_says():
    params = SpaceParams(enabled=True, sensitive_depth_um=5.0, charge_diffusion_um=1.0)
    pixels, charges = track_charges(10.5, 10.5, 1.0, 0.0, 1, params, 4.86, 30, 30)
    centre = charges[pixels == 10 * 30 + 10][0] / charges.sum()
    share = math.erf(0.5 * 4.86 / (1.0 * math.sqrt(2))) ** 2  # a Gaussian of 1 um over a 4.86 um square
    assert centre == pytest.approx(share, rel=1e-3)


def test_a_burst_worked_by_hand():
    """Q = (e^0.75 - 1) Q_ref with thresholds 0.25: the log jumps 0.75, three ON events; it
    falls back through 0.5 and 0.25 (two OFF events) at tau ln(r / (e^L - 1))."""
    r = math.expm1(0.75)
    n_on, levels = burst_levels(r, 0.25, 0.25)
    assert n_on == 3 and levels == pytest.approx([0.5, 0.25])
    t = recovery_times_s(r, levels, 0.01)
    assert t == pytest.approx([0.01 * math.log(r / math.expm1(0.5)), 0.01 * math.log(r / math.expm1(0.25))])
    assert t == pytest.approx([0.005434, 0.013693], rel=1e-3)
    assert burst_levels(math.expm1(0.2), 0.25, 0.25) == (0, pytest.approx([]))  # under a threshold: nothing


def test_the_reference_charge_is_the_same_in_every_pixel():
    """Q_ref = I tau = 13.75 I_dark / (2 pi cutoff_hz): the bandwidth grows with the current."""
    q = reference_charge_c(np.array([0.0, 20.0, 2000.0, 2e6]), DARK_A, 3.0)
    assert q == pytest.approx(13.75 * DARK_A / (2 * math.pi * 3.0), rel=1e-9)


def stream(params, seed=4, width=64, height=48, intensity=2000.0, cutoff_hz=3.0):
    space = SpaceEvents(params, width, height, PITCH_M, DARK_A, cutoff_hz, seed)
    return space, np.full(width * height, intensity)


THETA = (np.full(64 * 48, 0.25), np.full(64 * 48, 0.25))


def run(params, times, **kwargs):
    space, intensity = stream(params, **kwargs)
    parts = [space.interval(t0, t1, intensity, 1.0, *THETA) for t0, t1 in zip(times[:-1], times[1:])]
    parts.append(space.due(10**15))
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}, space


def test_hits_make_sorted_labelled_bursts_on_and_then_off():
    params = SpaceParams(enabled=True, particle_flux_cm2_s=1e6)
    events, space = run(params, np.arange(0, 0.5, 0.01))
    assert space.hits > 50 and len(events["t"]) > 0 and (events["label"] == RADIATION).all()
    assert (np.diff(events["t"]) >= 0).all()
    pix = events["y"].astype(int) * 64 + events["x"]
    for i in np.unique(pix)[:20]:
        mine = events[pix == i] if isinstance(events, np.ndarray) else {k: v[pix == i] for k, v in events.items()}
        first_off = np.argmax(mine["p"] == 0) if (mine["p"] == 0).any() else len(mine["p"])
        assert (mine["p"][:first_off] == 1).all()  # ON at the hit, before its OFF tail
    # heavy nuclei and grazing tracks fire; a proton straight through does not (0.08 < 0.25)
    ratio = E_PAIRS_PER_UM * 5.0 * 1.602176634e-19 / (13.75 * DARK_A / (2 * math.pi * 3.0))
    assert burst_levels(ratio, 0.25, 0.25)[0] == 0


def test_the_same_events_however_the_intervals_are_split_in_calls():
    params = SpaceParams(enabled=True, particle_flux_cm2_s=1e6, row_column_hz=20.0)
    times = np.arange(0, 0.3, 0.01)
    whole, _ = run(params, times)
    space, intensity = stream(params)
    parts = [space.interval(t0, t1, intensity, 1.0, *THETA) for t0, t1 in zip(times[:-1], times[1:])]
    assert all((np.diff(p["t"]) >= 0).all() for p in parts)
    again = {k: np.concatenate([p[k] for p in [*parts, space.due(10**15)]]) for k in whole}
    assert all(np.array_equal(whole[k], again[k]) for k in whole)
    other, _ = run(params, times, seed=5)
    assert len(other["t"]) != len(whole["t"]) or not np.array_equal(other["t"], whole["t"])


def test_a_glitch_fires_a_whole_row_or_column_at_once():
    params = SpaceParams(enabled=True, row_column_hz=40.0, glitch_duration_s=1e-4)
    events, space = run(params, np.arange(0, 1.0, 0.01))
    assert space.glitches > 10 and (events["label"] == GLITCH).all()
    # every glitch: 64 events in one row or 48 in one column, within 100 us, one polarity
    t = events["t"]
    groups = np.split(np.arange(len(t)), np.flatnonzero(np.diff(t) > 200) + 1)
    sizes = sorted({len(g) for g in groups})
    assert set(sizes) <= {48, 64, 96, 112, 128}  # two glitches may overlap in time
    for g in groups:
        if len(g) in (48, 64):
            rows, cols, p = events["y"][g], events["x"][g], events["p"][g]
            assert (len(set(rows)) == 1 or len(set(cols)) == 1) and len(set(p)) == 1 and np.ptp(t[g]) <= 100


def test_hits_need_a_photoreceptor_bandwidth():
    with pytest.raises(ValueError, match="cutoff_hz > 0"):
        stream(SpaceParams(enabled=True, particle_flux_cm2_s=1.0), cutoff_hz=0.0)
    with pytest.raises(ValueError, match="events.space.particle_flux_cm2_s"):
        SpaceParams(particle_flux_cm2_s=-1.0)


@pytest.mark.accuracy
@given(normal_floats(-50.0, 50.0), st.integers(-60, 60), st.floats(0.05, 10.0))
def test_a_gaussians_cell_shares_are_within_2_eps_of_50_digits(centre, cell, sigma):
    """Its stated bound (docs/accuracy.md): each cell's share of the charge within 2 eps
    absolute of the Gaussian's integral over [c, c + 1) at 50 digits, for spreads of 0.05..10
    px anywhere in a 100-px span (in the tails the difference of two erfs near 1 keeps only
    that absolute accuracy: shares under 1e-9 are dropped, where it is 2e-7 relative)."""
    import mpmath as mp

    got = float(cell_shares(np.array([centre]), np.array([float(cell)]), sigma)[0])
    with mp.workdps(50):
        scale = mp.mpf(sigma) * mp.sqrt(2)
        exact = (mp.erf((cell + 1 - mp.mpf(centre)) / scale) - mp.erf((cell - mp.mpf(centre)) / scale)) / 2
        assert float(abs(got - exact)) <= 2 * np.finfo(float).eps


@pytest.mark.accuracy
@given(st.floats(1e-6, 1e12), st.floats(1e-3, 1.0), st.floats(1e-6, 10.0))
def test_the_recovery_times_are_within_their_bound_of_50_digits(charge_ratio, level_fraction, tau_s):
    """Its stated bound (docs/accuracy.md): the time the pixel's log falls back to a level L
    below its peak ln(1 + r), t = tau ln(r / (e^L - 1)), within 4 eps (tau + t) of 50 digits,
    for charges 1e-6..1e12 Q_ref, levels down to 1e-3 of the peak and tau 1 us..10 s (the
    log's argument near 1 as the level nears the peak: an absolute bound there)."""
    import mpmath as mp

    level = float(np.log1p(charge_ratio)) * level_fraction
    got = float(recovery_times_s(charge_ratio, np.array([level]), tau_s)[0])
    with mp.workdps(50):
        exact = mp.mpf(tau_s) * mp.log(mp.mpf(charge_ratio) / mp.expm1(mp.mpf(level)))
        assert float(abs(got - exact)) <= 4 * np.finfo(float).eps * (tau_s + float(abs(exact)))
