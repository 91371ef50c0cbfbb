"""The sensor model against the camera equation and black-body facts worked out by hand."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from normal_floats import flushed
from traj2events.config import section
from traj2events.sensor.laws import KNEE_DN
from traj2events.sensor.photocurrent import SensorParams, photocurrent_a, sensor_dn, solar_band

Q, H, C, K = 1.602176634e-19, 6.62607015e-34, 299792458.0, 1.380649e-23


def _sensor(**changes) -> SensorParams:
    return SensorParams.from_config({**section("events")["sensor"], **changes})


def test_whole_spectrum_share_is_one_and_mean_photon_energy_is_2_701_kT():
    # sigma T^4 (Stefan-Boltzmann) and <E> = pi^4 / (30 zeta(3)) k T for a black body
    share, photons_per_j = solar_band((5e-8, 1e-3), 5772.0)
    assert share == pytest.approx(1.0, abs=1e-3)
    assert 1.0 / photons_per_j == pytest.approx(np.pi**4 / (30 * 1.2020569031595942) * K * 5772.0, rel=1e-3)


def test_visible_band_holds_about_37_percent_of_the_sun():
    # 400-700 nm of a 5772 K black body: 36.6 % (the measured AM0 spectrum: ~38 %)
    share, _ = solar_band((4e-7, 7e-7), 5772.0)
    assert share == pytest.approx(0.366, abs=0.003)


def test_camera_equation_by_hand_in_a_narrow_band():
    # White Lambertian surface under the Sun at normal incidence: L = E / pi, so the image
    # irradiance is tau E / (4 N^2); in a 0.2 nm band at 550 nm each photon has h c / lambda.
    lam, width = 550e-9, 0.2e-9
    sensor = _sensor(f_number=2.8, optics_transmittance=0.8, pixel_pitch_m=10e-6, quantum_efficiency=0.6,
                     band_m=[lam - width / 2, lam + width / 2])  # fmt: skip
    e_sun = 1361.0
    b = 2 * H * C**2 / lam**5 / np.expm1(H * C / (lam * K * 5772.0))  # Planck, W m^-2 sr^-1 m^-1
    share = b * width / (5.670374419e-8 * 5772.0**4 / np.pi)
    watts_on_pixel = 0.8 * e_sun * share / (4 * 2.8**2) * (10e-6) ** 2
    expected = watts_on_pixel / (H * C / lam) * 0.6 * Q
    assert photocurrent_a(np.array([e_sun / np.pi]), sensor)[0] == pytest.approx(expected, rel=1e-4)


def test_knee_sits_at_the_dark_current_and_the_input_is_linear():
    sensor = _sensor()
    one_dark = sensor.dark_current_a / photocurrent_a(np.array([1.0]), sensor)[0]  # radiance giving I_dark
    dn = sensor_dn(np.array([0.0, one_dark, 2 * one_dark, 1e3 * one_dark]), sensor)
    assert dn == pytest.approx([0.0, KNEE_DN, 2 * KNEE_DN, 1e3 * KNEE_DN], rel=1e-12)
    assert sensor_dn(np.array([1.0], np.float32), sensor, np.float32).dtype == np.float32


def test_lunar_daylight_is_far_above_the_dark_current():
    # A sunlit regolith patch (I/F ~ 0.1 under 1361 W/m^2: L ~ 43 W/m^2/sr) gives pA, i.e.
    # thousands of dark currents: the knee only matters in shadows and the sky.
    current = photocurrent_a(np.array([0.1 * 1361 / np.pi]), _sensor())[0]
    assert 1e-12 < current < 1e-10


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("quantum_efficiency", 1.5, "events.sensor.quantum_efficiency: expected a value <= 1, got 1.5"),
        ("f_number", 0.0, "events.sensor.f_number: expected a value >= 0.5"),
        ("band_m", [7e-7, 4e-7], "events.sensor.band_m: expected [low, high]"),
        ("dark_current_a", -1e-15, "events.sensor.dark_current_a: expected a value >= 1e-21"),
    ],
)
def test_bad_sensor_values_name_the_key(key, value, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("(", r"\(").replace("]", r"\]")):
        _sensor(**{key: value})


def test_unknown_sensor_key_is_named():
    with pytest.raises(ValueError, match="events.sensor: unknown keys \\['aperture'\\]"):
        _sensor(aperture=2.0)


def test_the_emulator_white_is_the_radiance_at_255_dn_on_either_scale():
    from traj2events.sensor.photocurrent import emulator_white_w_m2_sr

    events = section("events")
    assert emulator_white_w_m2_sr({**events, "input": "display"}, 40.0) == 40.0
    white = emulator_white_w_m2_sr({**events, "input": "sensor"}, 40.0)
    assert sensor_dn(np.array([white]), _sensor())[0] == pytest.approx(255.0)
    assert white == pytest.approx(12.75 * 1e-15 / photocurrent_a(np.array([1.0]), _sensor())[0])  # 12.75 dark currents


def exact_solar_band(lo_m: float, hi_m: float, temperature_k: float) -> tuple:
    """Planck's law integrated over the band by mpmath's quadrature at 30 digits, over the
    total sigma T^4 / pi with sigma = 2 pi^5 k^4 / (15 h^3 c^2) of the SI's exact h, k, c:
    (share, photons per joule)."""
    import mpmath as mp

    from traj2events.sensor.photocurrent import BOLTZMANN_J_K, LIGHT_SPEED_M_S, PLANCK_J_S

    with mp.workdps(30):
        h, c, k, t = mp.mpf(PLANCK_J_S), mp.mpf(LIGHT_SPEED_M_S), mp.mpf(BOLTZMANN_J_K), mp.mpf(temperature_k)

        def planck(lam):
            return 2 * h * c**2 / lam**5 / mp.expm1(h * c / (lam * k * t))

        lo, hi = mp.mpf(lo_m), mp.mpf(hi_m)
        nodes = [lo * (hi / lo) ** (mp.mpf(i) / 8) for i in range(9)]  # log-spaced pieces
        in_band = mp.quad(planck, nodes)
        photons = mp.quad(lambda lam: planck(lam) * lam / (h * c), nodes)
        sigma = 2 * mp.pi**5 * k**4 / (15 * h**3 * c**2)
        return in_band / (sigma * t**4 / mp.pi), photons / in_band


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 20, 10))  # two 30-digit quadratures each
@given(st.floats(2e-7, 1e-5), st.floats(1e-4, 2.0), st.floats(3000.0, 10000.0))
def test_the_bands_share_and_photons_are_within_their_bound_of_planck(lo_m, log_ratio, temperature_k):
    """Its stated bound (docs/accuracy.md): the band's share of the Sun's power and its
    photons per joule within 1e-8 (x ln(hi / lo))^2 + 1e-10 relative of Planck's law
    integrated at 30 digits, x = max(hc / (lo k T), 5) (Wien's steep side), for bands from
    200 nm to 10 um wide to two decades and black bodies 3000-10000 K: the trapezoids' error
    on the 4001-point log grid, and the rounded Stefan-Boltzmann constant's (3e-11)."""
    hi_m = lo_m * 10.0**log_ratio
    share, photons_per_j = solar_band((lo_m, hi_m), temperature_k)
    exact_share, exact_photons = exact_solar_band(lo_m, hi_m, temperature_k)
    x = max(0.0143877688 / (lo_m * temperature_k), 5.0)  # hc / (lambda k T), m K over m K
    bound = 1e-8 * (x * np.log(hi_m / lo_m)) ** 2 + 1e-10
    assert float(abs(share - exact_share) / exact_share) <= bound
    assert float(abs(photons_per_j - exact_photons) / exact_photons) <= bound


@pytest.mark.accuracy
@given(st.floats(0.5, 32.0), st.floats(0.01, 1.0), st.floats(5e-7, 1e-4), st.floats(0.01, 1.0),
       st.floats(1e-18, 1e-10), st.floats(0.0, 1e4).map(lambda x: float(flushed(x, np.float32))))  # fmt: skip
def test_the_photocurrent_and_the_emulators_input_are_within_their_bound(f_number, tau, pitch, qe, dark, radiance):
    """Their stated bound (docs/accuracy.md): the camera equation's product, times the
    band's share and photons per joule (solar_band's own bound aside), within 8 eps
    relative of the same product at 50 digits; the emulator's float32 input within 2 eps32
    of it (the factor's rounding and the product's), for lenses f/0.5-f/32, pitches
    0.5-100 um, dark currents 1e-18-1e-10 A and radiances 0 or 1e-12 to 1e4 W m^-2 sr^-1
    (float32 numbers: no underflow)."""
    import mpmath as mp

    sensor = _sensor(f_number=f_number, optics_transmittance=tau, pixel_pitch_m=pitch, quantum_efficiency=qe,
                     dark_current_a=dark)  # fmt: skip
    share, photons_per_j = solar_band(sensor.band_m)
    with mp.workdps(50):
        amps = mp.pi * mp.mpf(tau) / (4 * mp.mpf(f_number) ** 2) * mp.mpf(pitch) ** 2 * mp.mpf(share)
        amps *= mp.mpf(photons_per_j) * mp.mpf(qe) * mp.mpf(Q) * mp.mpf(radiance)
        dn = amps * KNEE_DN / mp.mpf(dark)
    current = photocurrent_a(np.array([radiance]), sensor)[0]
    assert abs(current - float(amps)) <= 8 * np.finfo(float).eps * float(amps)
    got = sensor_dn(np.array([radiance], np.float32), sensor, np.float32)[0]
    assert abs(float(got) - float(dn)) <= 2 * np.finfo(np.float32).eps * float(dn)
