"""Presets of sensors that exist (src/traj2events/presets/): each value against the published
figure it comes from (worked here from the figure, not read back from the preset), the
layers of a config (defaults < preset < the config's own keys), and the events of a slow
edge sweep against the sensor's contrast threshold and latency."""

import math
from dataclasses import replace

import numpy as np
import pytest

from traj2events.config import resolve_config
from traj2events.defaults import preset, preset_names, with_preset
from traj2events.sensor.emulator import EventEmulator
from traj2events.sensor.laws import bandwidth_hz_scalar
from traj2events.settings.tree import default_config
from traj2events.stages.events import preset_params

LUMINOUS_EFFICACY_555_LM_W = 683.0  # the lux's definition, at 555 nm
PHOTON_555_J = 6.62607015e-34 * 299792458.0 / 555e-9
CHARGE_C = 1.602176634e-19
# Published figures: contrast thresholds (fractions), latency at 1 klux on the chip (s),
# the low-light end (lx), pitch (m), readout (events/s). docs/events.md "Sensor presets".
SENSORS = {
    "imx636": dict(on=0.25, off=0.25, latency_s=100e-6, low_lux=0.08, pitch_m=4.86e-6, rate_hz=1.066e9),
    "davis346": dict(
        on=0.143, off=0.225, latency_s=20e-6, low_lux=100e3 / 10 ** (120 / 20), pitch_m=18.5e-6, rate_hz=12e6
    ),
}


def photocurrent_at_lux(lux: float, pitch_m: float, quantum_efficiency: float) -> float:
    """A; illuminance on the chip at 555 nm: lux / 683 W/m^2, over the pixel's square."""
    return CHARGE_C * quantum_efficiency * lux / LUMINOUS_EFFICACY_555_LM_W / PHOTON_555_J * pitch_m**2


def test_the_named_sensors_are_presets():
    assert {"paper", "clean", "imx636", "davis346"} <= set(preset_names())


@pytest.mark.parametrize("name", SENSORS)
def test_each_value_is_its_published_figure(name):
    fig, values = SENSORS[name], preset(name)
    pixel, sensor = values["pixel"], {**default_config()["events"]["sensor"], **values["sensor"]}
    # a threshold of C: the intensity changes by the factor 1 + C
    assert pixel["theta_on"] == pytest.approx(math.log1p(fig["on"]), abs=1e-4)
    assert pixel["theta_off"] == pytest.approx(math.log1p(fig["off"]), abs=1e-4)
    assert sensor["pixel_pitch_m"] == fig["pitch_m"]
    # the dark current is the photocurrent at the low-light end
    dark_a = photocurrent_at_lux(fig["low_lux"], fig["pitch_m"], sensor["quantum_efficiency"])
    assert sensor["dark_current_a"] == pytest.approx(dark_a, rel=0.01)
    # at 1 klux the photoreceptor's time constant 1 / (2 pi f_c) is the published latency
    x_1klux = 20.0 * photocurrent_at_lux(1e3, fig["pitch_m"], sensor["quantum_efficiency"]) / dark_a
    tau_s = 1.0 / (2 * math.pi * bandwidth_hz_scalar(x_1klux, pixel["cutoff_hz"]))
    assert tau_s == pytest.approx(fig["latency_s"], rel=0.01)
    assert values["readout"]["max_event_rate_hz"] == fig["rate_hz"] and values["readout"]["mode"] == "delay"
    assert sensor["psf_diffraction"] and sensor["vignetting"]  # a lens, as a real camera has


def test_a_config_layers_defaults_preset_and_its_own_keys():
    own = {"preset": "imx636", "sensor": {"dark_current_a": 2e-15}, "readout": {"mode": "drop"},
           "pixel": {"sigma": 0.05}}  # fmt: skip
    events = resolve_config({"events": own})["events"]
    defaults = default_config()["events"]
    assert events["sensor"]["dark_current_a"] == 2e-15  # the config's own key
    assert events["sensor"]["pixel_pitch_m"] == 4.86e-6 and events["sensor"]["vignetting"] is True  # the preset's
    assert events["sensor"]["f_number"] == defaults["sensor"]["f_number"]  # the defaults' (not in the preset)
    assert events["readout"] == {**defaults["readout"], "max_event_rate_hz": 1.066e9, "mode": "drop"}
    assert events["pixel"] == {**preset("imx636")["pixel"], "sigma": 0.05}
    config = resolve_config({"events": own})
    assert with_preset(config, {"events": own}["events"]) == config  # applied twice: the same
    # the paper preset gives the pixel only: the sensor stays the defaults'
    assert resolve_config({})["events"]["sensor"] == defaults["sensor"]


def sweep(params, bright_x: float, contrast: float, duration_s: float, dt_s: float):
    """A slow edge crossing one pixel: its intensity rises linearly from bright / contrast to
    bright (the edge's share of the pixel). (events, times, intensity)."""
    times = np.arange(0.0, duration_s + dt_s / 2, dt_s)
    share = np.clip(times / duration_s, 0.0, 1.0)
    x = bright_x / contrast + (bright_x - bright_x / contrast) * share
    frames = np.broadcast_to(x[:, None, None], (len(times), 1, 2)).copy()
    events = EventEmulator(2, 1, params).process(frames, times)
    return events[events["x"] == 0], times, x


@pytest.mark.parametrize("name", SENSORS)
def test_a_slow_edge_sweep_fires_at_the_threshold_with_the_latency(name):
    """Noise off. Events every factor 1 + C of intensity; each lags the crossing of the
    unfiltered intensity by the photoreceptor's time constant there, which is the
    published latency at 1 klux (a first-order low-pass lags a slow ramp by its tau)."""
    fig, sensor = SENSORS[name], {**default_config()["events"]["sensor"], **preset(name)["sensor"]}
    params = preset_params(name, sigma=0.0, leak_hz=0.0, shot_noise_hz=0.0)
    x_1klux = 20.0 * photocurrent_at_lux(1e3, fig["pitch_m"], sensor["quantum_efficiency"]) / sensor["dark_current_a"]
    contrast = 4.0
    events, times, x = sweep(params, x_1klux, contrast, duration_s=0.02, dt_s=fig["latency_s"] / 50)
    n = math.floor(math.log(contrast) / params.theta_on)
    assert len(events) == n and (events["p"] == 1).all()
    # where the unfiltered log intensity crosses each threshold
    levels = np.log(x[0]) + params.theta_on * np.arange(1, n + 1)
    crossing_s = np.interp(levels, np.log(x), times)
    x_at = np.exp(levels)
    tau_s = 1.0 / (2 * np.pi * np.array([bandwidth_hz_scalar(v, params.cutoff_hz) for v in x_at]))
    lag_s = events["t"] * 1e-6 - crossing_s
    assert lag_s == pytest.approx(tau_s, rel=0.05)
    # the brightest crossing is within a threshold of 1 klux: its lag is the published latency's
    assert lag_s[-1] == pytest.approx(fig["latency_s"] * x_1klux / x_at[-1], rel=0.05)
    assert x_1klux / x_at[-1] < 1 + fig["on"]


@pytest.mark.parametrize("name", SENSORS)
def test_a_step_fires_only_beyond_the_contrast_threshold(name):
    params = replace(preset_params(name, sigma=0.0, leak_hz=0.0, shot_noise_hz=0.0), cutoff_hz=0.0)
    for polarity, key in ((1, "on"), (-1, "off")):
        for factor, fires in ((0.98, 0), (1.02, 1)):
            change = (1 + SENSORS[name][key] * factor) ** polarity
            frames = np.array([1e4, 1e4 * change])[:, None, None] * np.ones((2, 1, 1))
            assert len(EventEmulator(1, 1, params).process(frames, np.array([0.0, 0.01]))) == fires
