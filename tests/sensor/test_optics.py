"""The lens before the pixels (sensor/optics.py): the Airy pattern's encircled energy
against Rayleigh's formula and the published 83.8 % inside the first dark ring, the pixel
kernel's bounds and moments, cos^4 vignetting by hand, and the flux kept."""

import numpy as np
import pytest
from scipy import integrate, special

from traj2events.sensor.optics import airy_encircled_energy, airy_psf, psf_kernel, through_lens, vignetting

PITCH = 4.86e-6


def test_the_airy_pattern_holds_83_8_percent_inside_its_first_dark_ring():
    # First zero at r = 1.22 lambda N; energy inside: 83.8 % (Born & Wolf); at larger radii
    # 1 - J0(v)^2 - J1(v)^2 (Rayleigh), here against the PSF's own integral.
    wavelength, n = 550e-9, 2.0
    first_ring = 1.21967 * wavelength * n
    for r_max, expected in ((first_ring, 0.838), (3 * first_ring, None), (10e-6, None)):
        inside, _ = integrate.quad(lambda r: airy_psf(r, wavelength, n) * 2 * np.pi * r, 0, r_max, limit=400)
        rayleigh = airy_encircled_energy(r_max, wavelength, n)
        assert inside == pytest.approx(rayleigh, abs=1e-6)
        if expected:
            assert inside == pytest.approx(expected, abs=5e-4)


def test_a_gaussian_blur_kernel_has_the_erf_centre_and_sigma2_plus_1_12_variance():
    # A pixel collects the Gaussian over its square: the centre pixel erf(1 / (2 sqrt(2) s))^2
    # of it, over the window's share erf((R + 1/2) / (sqrt(2) s))^2 (the kernel keeps all the
    # light); along an axis, pixel i collects (erf((i + 1/2) / (sqrt(2) s)) - erf((i - 1/2) / ...)) / 2.
    s = 1.5
    kernel = psf_kernel(PITCH, 2.0, (4e-7, 7e-7), diffraction=False, lens_blur_um=s * PITCH * 1e6)
    centre = kernel.shape[0] // 2
    window = special.erf((centre + 0.5) / (np.sqrt(2) * s)) ** 2
    assert kernel[centre, centre] == pytest.approx(special.erf(0.5 / (np.sqrt(2) * s)) ** 2 / window, rel=1e-3)
    offsets = np.arange(kernel.shape[0]) - centre
    marginal = special.erf((offsets + 0.5) / (np.sqrt(2) * s)) - special.erf((offsets - 0.5) / (np.sqrt(2) * s))
    assert kernel.sum(axis=1) == pytest.approx(marginal / marginal.sum(), abs=2e-4)
    assert kernel.sum() == pytest.approx(1.0) and np.allclose(kernel, kernel.T) and np.allclose(kernel, kernel[::-1])


def test_the_centre_pixel_holds_between_its_inscribed_and_circumscribed_discs_energy():
    # A narrow band at 550 nm, f/8 (Airy core 5.4 um, wider than the pixel): the centre
    # pixel's share lies between the encircled energy at p/2 and at p/sqrt(2).
    kernel = psf_kernel(PITCH, 8.0, (549e-9, 551e-9), diffraction=True, lens_blur_um=0.0)
    centre = kernel[kernel.shape[0] // 2, kernel.shape[0] // 2]
    assert (
        airy_encircled_energy(PITCH / 2, 550e-9, 8.0) < centre < airy_encircled_energy(PITCH / np.sqrt(2), 550e-9, 8.0)
    )


def test_no_lens_is_a_pinhole():
    assert psf_kernel(PITCH, 2.0, (4e-7, 7e-7), False, 0.0).tolist() == [[1.0]]


def test_vignetting_is_cos4_of_the_field_angle():
    # 2 x 2 pixels, focal length 1 px: every pixel 0.5 px off both axes, cos^2 = 1 / 1.5.
    assert vignetting(2, 2, 1.0) == pytest.approx(np.full((2, 2), (1 / 1.5) ** 2))
    big = vignetting(101, 51, 100.0)
    assert big[25, 50] == 1.0 and big[0, 0] == pytest.approx(np.cos(np.arctan(np.hypot(50, 25) / 100)) ** 4)


def test_vignetting_through_a_distorting_lens_follows_the_ray_the_pixel_sees():
    """Barrel distortion brings a wider field onto the corner pixel: its falloff is cos^4
    of the angle of the ray OpenCV undistorts it to (larger than the pinhole's)."""
    import cv2

    from traj2events.geometry.distortion import Distortion

    lens = Distortion(k1=-0.3, k2=0.05)
    falloff = vignetting(101, 51, 100.0, lens)
    matrix = np.array([[100.0, 0, 50], [0, 100.0, 25], [0, 0, 1]])
    ray = cv2.undistortPoints(np.array([[[0.0, 0.0]]]), matrix, lens.coefficients,
                              criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-15))[0, 0]  # fmt: skip
    assert falloff[0, 0] == pytest.approx(np.cos(np.arctan(np.hypot(*ray))) ** 4, rel=1e-7)
    assert falloff[0, 0] < vignetting(101, 51, 100.0)[0, 0] and falloff[25, 50] == 1.0


def test_the_lens_keeps_flux_and_spreads_a_point_as_its_kernel():
    kernel = psf_kernel(PITCH, 2.0, (4e-7, 7e-7), True, 3.0)
    flat = np.full((1, 20, 30), 7.0, np.float32)
    assert through_lens(flat, kernel, None) == pytest.approx(flat, rel=1e-6)  # edges repeated: no loss
    point = np.zeros((1, 21, 21), np.float32)
    point[0, 10, 10] = 1.0
    spread = through_lens(point, kernel, None)[0]
    r = kernel.shape[0] // 2
    assert spread[10 - r : 11 + r, 10 - r : 11 + r] == pytest.approx(kernel, abs=1e-7)
