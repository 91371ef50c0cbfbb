"""The reflectance laws' parameters as the shaders take them (shaders/reflectance.glsl)."""

from __future__ import annotations

import numpy as np

from ..scene.earthshine import Earth
from ..scene.reflectance import ReflectanceParams, bihemispherical_albedo, max_radiance_factor
from ..scene.sun import Sun


def hapke_r0_float32(w: float) -> float:
    """Hapke's r0 = (1 - sqrt(1 - w)) / (1 + sqrt(1 - w)) in float32, operation by operation
    as GLSL computes it: the shaders' `hapke_r0` uniform, with the bits they would get
    computing it themselves at every pixel (once per frame instead: 2-4 % of a braking
    frame on llvmpipe)."""
    gamma = np.sqrt(np.float32(1.0) - np.float32(w))
    return float((np.float32(1.0) - gamma) / (np.float32(1.0) + gamma))


def lobe_width_float32(b: float) -> float:
    """Hapke's b (declared < 1) as the shaders' float32 `b` uniform: rounded, but to at
    most float32's largest below 1, 1 - 2^-24. b within 2^-25 of 1 would round to 1, whose
    lobe (1 - b^2) / base^1.5 is 0 / 0, a NaN, at its peak (exact opposition)."""
    return float(min(np.float32(b), np.nextafter(np.float32(1.0), np.float32(0.0))))


def surge_width_float32(h: float) -> float:
    """Hapke's h (declared > 0) as the shaders' float32 `hw` uniform: rounded, but to at
    least 2^-64. Below float32's least normal, 2^-126, h would reach them as 0 (GPUs flush
    subnormals) and the surge B0 h' / (h' + sqrt(1 - cos g)) be 0 / 0 at exact opposition,
    where it is B0 for every h > 0; and B0 h' must stay normal too (an h of 2^-126 with B0
    0.5 flushed the surge to 0). The floor changes no float32 surge: away from opposition
    sqrt(1 - cos g) >= 2^-12 in float32, so an h below 2^-64 adds < 3e-16 B0 there."""
    return float(max(np.float32(h), np.float32(2.0**-64)))


def law_uniforms(reflectance: ReflectanceParams, sun: Sun, earth: Earth | None = None) -> dict:
    """The uniforms of reflectance.glsl (`earth` None: no earthshine), and `radiance_max`:
    the law's largest direct light plus the most scattered light there can be
    (scattering.py: S <= 1) and earthshine, W m^-2 sr^-1."""
    bounce_albedo = bihemispherical_albedo(reflectance)
    earthshine = earth.irradiance_w_m2(sun.irradiance_w_m2, sun.direction) if earth else 0.0
    most = max_radiance_factor(reflectance) + bounce_albedo**2 + bounce_albedo * earthshine / sun.irradiance_w_m2
    return {
        "sun_dir": sun.direction,
        "irradiance": float(sun.irradiance_w_m2),
        "model": 0 if reflectance.model == "hapke" else 1,
        "w": float(reflectance.single_scattering_albedo),
        "hapke_r0": hapke_r0_float32(reflectance.single_scattering_albedo),
        "b": lobe_width_float32(reflectance.phase_b),
        "c": float(reflectance.phase_c),
        "b0": float(reflectance.opposition_b0),
        "hw": surge_width_float32(reflectance.opposition_h),
        "albedo": float(reflectance.albedo),
        "bounce_albedo": bounce_albedo,
        "earth_dir": earth.direction if earth else np.array([0.0, 0.0, -1.0]),
        "earth_irradiance": earthshine,
        "radiance_max": float(most * sun.irradiance_w_m2 / np.pi),
    }
