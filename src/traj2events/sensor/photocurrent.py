"""The event sensor behind its lens: rendered radiance -> photocurrent per pixel, and the
emulator's input in units tied to that photocurrent (docs/events.md "Sensor model").

    E_image = pi tau L_band / (4 N^2)               camera equation, object at infinity
    Phi     = E_image p^2 / E_photon                 photons per second on the pixel
    I_ph    = q QE Phi                               photocurrent, A

L_band is the rendered radiance's share inside the sensor's band: the renderer's radiance
is of the whole solar spectrum (1361 W/m^2 at 1 AU), the Sun is taken as a 5772 K black
body and the regolith as grey, so the share and the mean photon energy come from Planck's
law over the band. The lens's point-spread function and cos^4 fall-off, when on, act on
the radiance before this (optics.py).

The emulator's input is the photocurrent in units of the dark current times the 20 DN
knee of its lin-log law, x = 20 I_ph / I_dark: the log response ln(I_ph + I_dark) of a
real photoreceptor is linear below the dark current and logarithmic above it, which is
what the emulator's knee does at x = 20. Its bandwidth law (proportional to x + 20, so to
I_ph + I_dark) and its shot-noise law (falling with x) then refer to the photocurrent too.
"""

from __future__ import annotations

import numpy as np

from ..settings.events import SensorParams
from .laws import KNEE_DN

ELEMENTARY_CHARGE_C = 1.602176634e-19
PLANCK_J_S = 6.62607015e-34
LIGHT_SPEED_M_S = 299792458.0
BOLTZMANN_J_K = 1.380649e-23
STEFAN_BOLTZMANN_W_M2_K4 = 5.670374419e-8
SUN_TEMPERATURE_K = 5772.0  # IAU 2015 nominal effective temperature


def planck_spectral_radiance(wavelength_m: np.ndarray, temperature_k: float) -> np.ndarray:
    """Black body B_lambda(T), W m^-2 sr^-1 m^-1."""
    lam = np.asarray(wavelength_m, dtype=np.float64)
    x = PLANCK_J_S * LIGHT_SPEED_M_S / (lam * BOLTZMANN_J_K * temperature_k)
    return 2.0 * PLANCK_J_S * LIGHT_SPEED_M_S**2 / lam**5 / np.expm1(x)


def solar_band(band_m: tuple[float, float], temperature_k: float = SUN_TEMPERATURE_K) -> tuple[float, float]:
    """(share of the Sun's power inside the band, photons per joule inside it) for a black
    body at `temperature_k`: trapezoids on a fine log grid (the total from Stefan-Boltzmann).
    Both within 1e-8 (x ln(hi / lo))^2 + 1e-10 relative of Planck's law integrated exactly,
    x = max(hc / (lo k T), 5), for bands 200 nm..10 um up to two decades wide and
    3000-10000 K (docs/accuracy.md)."""
    grid = np.geomspace(band_m[0], band_m[1], 4001)  # log-spaced: wide bands too
    spectrum = planck_spectral_radiance(grid, temperature_k)
    in_band = float(np.trapezoid(spectrum, grid))
    total = STEFAN_BOLTZMANN_W_M2_K4 * temperature_k**4 / np.pi  # W m^-2 sr^-1
    photons = float(np.trapezoid(spectrum * grid / (PLANCK_J_S * LIGHT_SPEED_M_S), grid))
    return in_band / total, photons / in_band


def amps_per_radiance(sensor: SensorParams) -> float:
    """Photocurrent (A) per unit of rendered (whole-spectrum) radiance (W m^-2 sr^-1)."""
    share, photons_per_j = solar_band(sensor.band_m)
    image_irradiance = np.pi * sensor.optics_transmittance / (4.0 * sensor.f_number**2)
    return (
        image_irradiance
        * sensor.pixel_pitch_m**2
        * share
        * photons_per_j
        * sensor.quantum_efficiency
        * ELEMENTARY_CHARGE_C
    )


def photocurrent_a(radiance_w_m2_sr: np.ndarray, sensor: SensorParams) -> np.ndarray:
    """Photocurrent per pixel (A) from the rendered radiance."""
    return np.asarray(radiance_w_m2_sr, dtype=np.float64) * amps_per_radiance(sensor)


def dn_per_radiance(sensor: SensorParams) -> float:
    """The emulator's input per unit radiance: photocurrent in dark currents times the
    20 DN knee (so the knee of its lin-log law sits at the dark current). One factor, so
    that the emulator can apply it to float32 frames itself (EventEmulator's input_scale)."""
    return amps_per_radiance(sensor) * (KNEE_DN / sensor.dark_current_a)


def sensor_dn(radiance_w_m2_sr: np.ndarray, sensor: SensorParams, dtype=np.float64) -> np.ndarray:
    """Rendered radiance -> the emulator's input through the sensor model."""
    return np.asarray(radiance_w_m2_sr, dtype=dtype) * dtype(dn_per_radiance(sensor))


def emulator_white_w_m2_sr(events: dict, display_white_w_m2_sr: float) -> float:
    """The radiance the emulator's input puts at 255 DN for the config's `events` section:
    the display white (input: display) or the radiance of 12.75 dark currents (sensor).
    Both inputs are radiance times a constant; this is the constant's inverse, times 255."""
    if events["input"] == "display":
        return display_white_w_m2_sr
    return 255.0 / dn_per_radiance(SensorParams.from_config(events["sensor"]))
