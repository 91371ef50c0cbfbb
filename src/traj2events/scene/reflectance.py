"""Reflectance laws of the lunar regolith, as radiance factor I/F.

Both laws exist twice: here in numpy (the reference, tested) and in
`renderer/shaders/reflectance.glsl` (what the renderer runs: the terrain shaders include it); tests
render a flat plane and compare.
Angles: incidence i (Sun from the surface normal), emission e (camera from the normal),
phase g (Sun to camera, seen from the surface); mu0 = cos i, mu = cos e.
Radiance: L = (I/F) E_sun / pi  (W m^-2 sr^-1), with E_sun the Sun's irradiance.

Hapke (Hapke 1981, 2002; the paper's choice), without the macroscopic-roughness
correction (the terrain's relief is modelled as geometry instead):
    I/F = (w / 4) mu0 / (mu0 + mu) [ (1 + B(g)) P(g) + H(mu0) H(mu) - 1 ]
    B(g) = B0 / (1 + tan(g / 2) / h)                          (shadow-hiding opposition)
    P(g) = (1 + c)/2 HG(b, g) + (1 - c)/2 HG(-b, g),  HG(b, g) = (1 - b^2) / (1 - 2 b cos g + b^2)^1.5
           (the double Henyey-Greenstein function of Hapke 2012, ch. 6, in phase angle:
           HG(b, g) peaks at g = 0 for b > 0, so c > 0 weights the backward lobe and the
           Moon is brightest toward the Sun)
    H(x) = 1 / (1 - w x (r0 + (1 - 2 r0 x)/2 ln((1 + x)/x))),  r0 = (1 - sqrt(1-w)) / (1 + sqrt(1-w))
Lunar-Lambert (McEwen 1991, 1996):
    I/F = A [ 2 L(g) mu0 / (mu0 + mu) + (1 - L(g)) mu0 ],
    L(g) = 1 - 0.019 g + 2.42e-4 g^2 - 1.46e-6 g^3     (g in degrees; clipped to [0, 1],
           the polynomial leaves it beyond ~110 deg where the fit has no data)
"""

from __future__ import annotations

import numpy as np

from ..settings.render import REFLECTANCE_MODELS, ReflectanceParams

MODELS = REFLECTANCE_MODELS


def chandrasekhar_h(x: np.ndarray, w: float) -> np.ndarray:
    """Hapke (2002) approximation of Chandrasekhar's H function: within 1 % of the exact H
    for x 1e-4..1 and w up to 0.999 (worst 0.96 % at w 0.99, x 1; docs/accuracy.md)."""
    x = np.asarray(x, dtype=float)
    gamma = np.sqrt(1.0 - w)
    r0 = (1.0 - gamma) / (1.0 + gamma)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(x > 0, np.log((1.0 + x) / np.maximum(x, 1e-300)), 0.0)
    return 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * log_term))


def henyey_greenstein(b: float, cos_g: np.ndarray) -> np.ndarray:
    """One Henyey-Greenstein lobe in phase angle g: backscattering (peak at g = 0) for
    b > 0, forward scattering (peak at g = 180 deg) for b < 0. Its base is written
    (1 - |b|)^2 + 2 |b| (1 -+ cos g), a sum of positives: the textbook 1 - 2 b cos g + b^2
    cancels near the lobe's peak as |b| -> 1 (0.1 relative off at b = 1 - 4e-9)."""
    a = abs(b)
    toward_peak = np.asarray(cos_g, dtype=float) if b >= 0 else -np.asarray(cos_g, dtype=float)
    return (1.0 - a) * (1.0 + a) / ((1.0 - a) ** 2 + 2.0 * a * (1.0 - toward_peak)) ** 1.5


def hapke_phase(b: float, c: float, cos_g: np.ndarray) -> np.ndarray:
    """Hapke's double-lobed phase function P(g): a backward lobe weighted (1 + c)/2 and a
    forward lobe weighted (1 - c)/2; it integrates to 1 over the sphere (4 pi sr)."""
    return 0.5 * (1 + c) * henyey_greenstein(b, cos_g) + 0.5 * (1 - c) * henyey_greenstein(-b, cos_g)


def opposition_surge(cos_g: np.ndarray, b0: float, h: float) -> np.ndarray:
    """Shadow hiding's B(g) = B0 / (1 + tan(g / 2) / h), with tan(g / 2) = sqrt((1 - cos g)
    / (1 + cos g)): written B0 h sqrt(1 + cos g) / (h sqrt(1 + cos g) + sqrt(1 - cos g)),
    whose denominator never vanishes (0 at g = 180 deg) and which is within 4 eps of B
    for every cos g; through arccos and tan it was pi eps / (pi - g) off near 180 deg."""
    cos_g = np.clip(np.asarray(cos_g, dtype=float), -1.0, 1.0)
    toward = h * np.sqrt(1.0 + cos_g)
    return b0 * toward / (toward + np.sqrt(1.0 - cos_g))


def hapke_radiance_factor(mu0: np.ndarray, mu: np.ndarray, cos_g: np.ndarray, p: ReflectanceParams) -> np.ndarray:
    """Hapke's law (module docstring); 0 where mu0 or mu <= 0. Domain and bound: mu0, mu in
    (0, 1], any phase, every w, b, c the config accepts, B0 0..10, h 1e-4..10: within 8 eps
    of its terms, (w / 4) mu0 / (mu0 + mu) [(1 + B) P + H(mu0) H(mu)], of the law at 50
    digits (the -1 cancels against H H only; docs/accuracy.md)."""
    mu0, mu = np.asarray(mu0, dtype=float), np.asarray(mu, dtype=float)
    cos_g = np.clip(np.asarray(cos_g, dtype=float), -1.0, 1.0)
    w = p.single_scattering_albedo
    opposition = opposition_surge(cos_g, p.opposition_b0, p.opposition_h)
    phase = hapke_phase(p.phase_b, p.phase_c, cos_g)
    multiple = chandrasekhar_h(mu0, w) * chandrasekhar_h(mu, w) - 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        rf = 0.25 * w * mu0 / (mu0 + mu) * ((1.0 + opposition) * phase + multiple)
    return np.where((mu0 > 0) & (mu > 0), rf, 0.0)


def lunar_lambert_radiance_factor(
    mu0: np.ndarray, mu: np.ndarray, cos_g: np.ndarray, p: ReflectanceParams
) -> np.ndarray:
    """McEwen's law (module docstring); 0 where mu0 or mu <= 0. Domain and bound: mu0, mu
    in (0, 1], any phase: within 4 eps relative plus 20 eps A absolute of the law at 50
    digits (the limb polynomial's rounding near its root, weight <= 2; docs/accuracy.md)."""
    mu0, mu, cos_g = (np.asarray(a, dtype=float) for a in (mu0, mu, cos_g))
    g = np.degrees(np.arccos(np.clip(cos_g, -1.0, 1.0)))
    limb = np.clip(1.0 - 0.019 * g + 2.42e-4 * g**2 - 1.46e-6 * g**3, 0.0, 1.0)  # the fit turns negative past ~110 deg
    with np.errstate(invalid="ignore", divide="ignore"):
        rf = p.albedo * (2.0 * limb * mu0 / (mu0 + mu) + (1.0 - limb) * mu0)
    return np.where((mu0 > 0) & (mu > 0), rf, 0.0)


def radiance_factor(mu0: np.ndarray, mu: np.ndarray, cos_g: np.ndarray, p: ReflectanceParams) -> np.ndarray:
    law = hapke_radiance_factor if p.model == "hapke" else lunar_lambert_radiance_factor
    return law(mu0, mu, cos_g, p)


def angles(normal: np.ndarray, to_sun: np.ndarray, to_camera: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(mu0, mu, cos g) from unit vectors (..., 3): surface normal, toward the Sun, toward the camera."""
    return (np.sum(normal * to_sun, axis=-1), np.sum(normal * to_camera, axis=-1), np.sum(to_sun * to_camera, axis=-1))


def max_radiance_factor(p: ReflectanceParams, n: int = 61) -> float:
    """Largest I/F the law gives over incidence, emission and azimuth (a grid search with
    5 % headroom): the renderer clamps interpolated radiance to it."""
    angle = np.linspace(0.0, np.pi / 2 * 0.999, n)
    azimuth = np.linspace(0.0, np.pi, n)
    i, e, a = np.meshgrid(angle, angle, azimuth, indexing="ij")
    cos_g = np.cos(i) * np.cos(e) + np.sin(i) * np.sin(e) * np.cos(a)
    return 1.05 * float(np.max(radiance_factor(np.cos(i), np.cos(e), cos_g, p)))


def hemispherical_albedo(law, mu0: np.ndarray, n: int = 48) -> np.ndarray:
    """Directional-hemispherical albedo A(mu0) = (1 / (pi mu0)) integral of I/F mu dOmega
    over the emission hemisphere: the share of the light arriving at incidence mu0 that
    leaves the surface; `law(mu0, mu, cos_g)` gives I/F (Gauss-Legendre in mu and azimuth).
    Lambert's I/F = A mu0 gives A."""
    nodes, weights = np.polynomial.legendre.leggauss(n)
    mu, w_mu = 0.5 * (nodes + 1), 0.5 * weights  # on (0, 1)
    phi, w_phi = np.pi * (nodes + 1), np.pi * weights  # on (0, 2 pi)
    mu0 = np.asarray(mu0, float)[..., None, None]
    cos_g = mu0 * mu[:, None] + np.sqrt(1 - mu0**2) * np.sqrt(1 - mu[:, None] ** 2) * np.cos(phi)[None, :]
    integrand = law(mu0, mu[:, None], cos_g) * mu[:, None] * w_mu[:, None] * w_phi[None, :]
    return integrand.sum(axis=(-2, -1)) / (np.pi * mu0[..., 0, 0])


def bihemispherical_albedo(p: ReflectanceParams, n: int = 48) -> float:
    """A = 2 integral of A(mu0) mu0 dmu0 (the surface's albedo under light from every
    direction): the albedo of the one-bounce scattering into shadows (scattering.py)."""
    nodes, weights = np.polynomial.legendre.leggauss(n)
    mu0 = 0.5 * (nodes + 1)
    albedo = hemispherical_albedo(lambda a, b, c: radiance_factor(a, b, c, p), mu0, n)
    return float(np.sum(2 * albedo * mu0 * 0.5 * weights))
