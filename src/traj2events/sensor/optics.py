"""The lens between the scene and the pixels: point-spread function and vignetting, applied
to the linear radiance on the sensor's grid before the pixel's log (events.sensor).

Diffraction by a circular aperture at f-number N gives, at wavelength lambda, the Airy
pattern (irradiance per unit power, r from the geometric image point)
    PSF(r) = pi / (4 (lambda N)^2) [2 J1(v) / v]^2,   v = pi r / (lambda N),
whose encircled energy is 1 - J0(v)^2 - J1(v)^2 (Rayleigh); over the sensor's band its
wavelengths are weighted by the Sun's photons (a 5772 K black body, as the photocurrent's
law). A lens's own blur (aberrations, defocus) is taken as a Gaussian of standard deviation
`lens_blur_um`, convolved with it. A pixel collects the PSF over its own square: the
kernel's weight at offset (i, j) pixels is the PSF's integral over that pixel, summed on a
grid of 16 x 16 points per pixel, over the smallest window holding 98 % of the PSF's
energy (at most 8 pixels out), normalised to 1 (no light lost, none made).

Natural vignetting: the image irradiance falls off as cos^4 of the field angle theta,
cos theta = f / sqrt(f^2 + x^2 + y^2) with (x, y) from the principal point in pixels.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, special

from ..geometry.distortion import PINHOLE, Distortion
from .photocurrent import SUN_TEMPERATURE_K, planck_spectral_radiance

SUBSAMPLES = 16  # points per pixel side integrating the PSF over a pixel
HELD_ENERGY = 0.98  # the kernel's window holds this share of the PSF's energy
MAX_RADIUS_PX = 8
WAVELENGTHS = 16  # samples of the band


def airy_psf(r_m: np.ndarray, wavelength_m: float, f_number: float) -> np.ndarray:
    """Irradiance per unit power (m^-2) at distance r from the image point."""
    scale = wavelength_m * f_number
    v = np.pi * np.asarray(r_m, float) / scale
    with np.errstate(invalid="ignore", divide="ignore"):
        amplitude = np.where(v > 1e-8, 2.0 * special.j1(v) / v, 1.0)
    return np.pi / (4.0 * scale**2) * amplitude**2


def airy_encircled_energy(r_m: np.ndarray, wavelength_m: float, f_number: float) -> np.ndarray:
    """Share of the Airy pattern's power within radius r (Rayleigh: 1 - J0^2 - J1^2)."""
    v = np.pi * np.asarray(r_m, float) / (wavelength_m * f_number)
    return 1.0 - special.j0(v) ** 2 - special.j1(v) ** 2


def band_wavelengths(band_m: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """(wavelengths, weights summing to 1): the band's midpoints weighted by solar photons."""
    edges = np.linspace(band_m[0], band_m[1], WAVELENGTHS + 1)
    wavelengths = 0.5 * (edges[1:] + edges[:-1])
    photons = planck_spectral_radiance(wavelengths, SUN_TEMPERATURE_K) * wavelengths
    return wavelengths, photons / photons.sum()


def psf_kernel(
    pixel_pitch_m: float, f_number: float, band_m: tuple[float, float], diffraction: bool, lens_blur_um: float
) -> np.ndarray:
    """(2R + 1, 2R + 1) weights summing to 1: the share of a point's light each pixel
    around it collects (module docstring); [[1.0]] with neither diffraction nor blur."""
    if not diffraction and lens_blur_um <= 0:
        return np.ones((1, 1))
    wavelengths, weights = band_wavelengths(band_m)
    sigma_m = lens_blur_um * 1e-6
    # The radius holding HELD_ENERGY: Airy's (the reddest wavelength, the widest) and the
    # Gaussian's (1 - exp(-r^2 / 2 sigma^2)), added in quadrature.
    r_airy = 0.0
    if diffraction:
        r = np.linspace(0.0, MAX_RADIUS_PX * pixel_pitch_m, 4001)
        held = airy_encircled_energy(r, wavelengths[-1], f_number)
        r_airy = r[min(np.searchsorted(held, HELD_ENERGY), len(r) - 1)]
    r_gauss = sigma_m * np.sqrt(-2.0 * np.log(1.0 - HELD_ENERGY))
    radius = int(np.clip(np.ceil(np.hypot(r_airy, r_gauss) / pixel_pitch_m - 0.5), 1, MAX_RADIUS_PX))
    side = 2 * radius + 1
    # Sample points at the centres of SUBSAMPLES^2 sub-squares of every pixel of the window.
    at = (np.arange(side * SUBSAMPLES) + 0.5) / SUBSAMPLES - radius - 0.5  # pixels from the centre
    xx, yy = np.meshgrid(at * pixel_pitch_m, at * pixel_pitch_m, indexing="ij")
    if diffraction:
        r = np.hypot(xx, yy)
        fine = sum(w * airy_psf(r, lam, f_number) for lam, w in zip(wavelengths, weights))
    else:  # a point: the Gaussian below spreads it
        fine = np.zeros_like(xx)
        middle = len(at) // 2  # the centre falls between four samples
        fine[middle - 1 : middle + 1, middle - 1 : middle + 1] = 0.25
    if sigma_m > 0:
        sigma_samples = sigma_m / pixel_pitch_m * SUBSAMPLES
        fine = ndimage.gaussian_filter(fine, sigma_samples, mode="constant", truncate=6.0)
    kernel = fine.reshape(side, SUBSAMPLES, side, SUBSAMPLES).sum(axis=(1, 3))
    return kernel / kernel.sum()


def vignetting(width: int, height: int, focal_px: float, distortion: Distortion = PINHOLE) -> np.ndarray:
    """(height, width) cos^4 of each pixel's field angle (principal point at the centre):
    the angle of the scene's ray that reaches it, through the lens's `distortion`."""
    x = np.arange(width) - (width - 1) / 2
    y = np.arange(height) - (height - 1) / 2
    if distortion.is_pinhole:
        cos2 = focal_px**2 / (focal_px**2 + x[None, :] ** 2 + y[:, None] ** 2)
    else:
        a, b = distortion.undistort(x[None, :] / focal_px, y[:, None] / focal_px)
        cos2 = 1.0 / (1.0 + a * a + b * b)
    return cos2**2


def through_lens(frames: np.ndarray, kernel: np.ndarray, falloff: np.ndarray | None) -> np.ndarray:
    """(n, H, W) linear radiance (or photocurrent) through the lens: each frame convolved
    with the kernel (the border's pixels repeated beyond the edge: the light from outside
    the rendered field is taken as its edge's), times the vignetting `falloff` if any."""
    out = np.empty(frames.shape, np.float32)
    for k, frame in enumerate(frames):
        blurred = ndimage.correlate(frame, kernel[::-1, ::-1].astype(np.float32), mode="nearest")
        out[k] = blurred if falloff is None else blurred * falloff
    return out
