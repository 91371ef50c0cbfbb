"""The reflectance laws as the shaders evaluate them (shaders/reflectance.glsl, with
law_uniforms' uniforms), drawn by OpenGL one fragment per query, against the laws at 50
digits on the same float32 inputs; Hapke's r0 as the shaders take it."""

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import example, given, reject, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from declared_values import declared_values
from fragment_queries import FragmentQueries
from normal_floats import SMALLEST
from reflectance_50_digit import hapke_50_digit, lunar_lambert_50_digit
from traj2events.renderer.law_uniforms import hapke_r0_float32, law_uniforms
from traj2events.scene.reflectance import ReflectanceParams
from traj2events.scene.sun import Sun
from traj2events.settings import render

EPS32 = float(np.finfo(np.float32).eps)
LEAST_NORMAL32 = float(np.finfo(np.float32).tiny)  # 2^-126: GPUs may flush what is below to 0
ALBEDOS = ("single_scattering_albedo", "albedo")  # the law's factors: kept above float32's underflow
QUERIES = 128  # per example: one draw
# r_F at each query's (mu0, mu, cos g), the shaders' own path from cosines: mu0 times the
# law per mu0 at the phase term (reflectance_factor_of_phase, less its dot products)
REFLECTANCE_FACTOR = "vec4(query(0).x * law_per_mu0(query(0).x, query(0).y, phase_term(query(0).z)), 0.0, 0.0, 0.0)"


@pytest.mark.parametrize("w, r0", [(0.36, 1.0 / 9.0), (0.75, 1.0 / 3.0), (0.0, 0.0), (1.0, 1.0)])
def test_hapke_r0_for_the_shaders_is_the_published_formula(w, r0):
    """r0 = (1 - g) / (1 + g), g = sqrt(1 - w): g = 0.8 and 0.5 by hand, and the limits."""
    assert hapke_r0_float32(w) == pytest.approx(r0, rel=1e-6, abs=1e-7)


@pytest.fixture(scope="module")
def shaders_law():
    with FragmentQueries('#include "reflectance.glsl"', REFLECTANCE_FACTOR, QUERIES) as queries:
        yield queries


def cosines(low: float) -> st.SearchStrategy:
    """QUERIES float32 cosines from `low` to 1 (their ends, and next to them, included)."""
    return arrays(np.float32, QUERIES, elements=st.floats(float(np.float32(low)), 1.0, width=32))


def one_query(mu0: float, mu: float, cos_g: float) -> tuple:
    """A counterexample's query, at every fragment."""
    return tuple(np.full(QUERIES, x, np.float32) for x in (mu0, mu, cos_g))


def as_the_shaders_take_it(uniforms: dict) -> SimpleNamespace:
    """The law's parameters as its float32 uniforms hold them, for the 50-digit law (w and b
    may round to 1, which the config's checks refuse)."""
    names = {"w": "single_scattering_albedo", "b": "phase_b", "c": "phase_c", "b0": "opposition_b0",
             "hw": "opposition_h", "albedo": "albedo"}  # fmt: skip
    return SimpleNamespace(**{law: float(np.float32(uniforms[name])) for name, law in names.items()})


@pytest.mark.accuracy
@settings(max_examples=max(settings.default.max_examples // 6, 10), deadline=None)  # law_uniforms: 80 ms each
# The search's finds, each beyond its bound before its fix (docs/accuracy.md):
# pow(base, 1.5) as exp2(1.5 log2 base), 17 eps32 of the terms at a lobe's peak as b -> 1;
@example({"model": "hapke", "phase_b": 0.9999996423721313, "phase_c": 0.89}, *one_query(2.2e-6, 3.2e-12, 1.0))
# b within 2^-25 of 1 reached the shaders as 1: the lobe 0 / 0 at its peak, a NaN;
@example({"model": "hapke", "phase_b": 0.99999999}, *one_query(0.5, 0.5, 1.0))
# h below float32's least normal reached them as 0: the surge 0 / 0 at opposition;
@example({"model": "hapke", "opposition_h": 2e-94}, *one_query(0.5, 0.5, 1.0))
# h at float32's least normal: B0 h' subnormal, flushed, the surge 0 at opposition;
@example({"model": "hapke", "opposition_b0": 0.5, "opposition_h": 1.4e-45}, *one_query(1.0, 1.0, 1.0))
# llvmpipe's acos 1.6e-4 rad off (GLSL allows 4096 ulp): L(g) 1.3e-4 of A off near its root.
@example({"model": "lunar-lambert", "albedo": 0.8}, *one_query(4.622861e-12, 4.692601e-12, -0.24086848))
@given(declared_values(render.ReflectanceParams, normal=True), cosines(1e-12), cosines(1e-12), cosines(-1.0))
def test_the_shaders_law_is_within_its_bound_of_its_50_digit_value(shaders_law, reflectance, mu0, mu, cos_g):
    """Its stated bound (docs/accuracy.md), over grazing light and view (mu0, mu 1e-12..1),
    every phase and every parameter the config accepts (the albedos w, A at least float32's
    1e-12: normal_floats), on the uniforms' float32 values:
    Hapke within 8 eps32 of its terms (as the numpy law's 8 eps) plus float32's least
    normal; Lunar-Lambert within 16 eps32 (r_F + A), its limb polynomial's rounding near
    its root (~110 deg) as in float64. On llvmpipe; TRAJ2EVENTS_TEST_BACKEND=egl on a GPU."""
    # the albedos away from float32's underflow (normal_floats): w 2e-38 made w / 4 subnormal, flushed
    reflectance = {k: max(v, SMALLEST[np.float32]) if k in ALBEDOS else v for k, v in reflectance.items()}
    try:
        law = ReflectanceParams(**reflectance)
    except ValueError:
        reject()  # (declared_values draws to an open bound; the config's check refuses it)
    uniforms = law_uniforms(law, Sun(1.496e11, 0.0, 30.0))
    shaders_law.uniforms(**{name: value for name, value in uniforms.items() if name != "radiance_max"})
    inputs = np.zeros((1, QUERIES, 4), np.float32)
    inputs[0, :, 0], inputs[0, :, 1], inputs[0, :, 2] = mu0, mu, cos_g
    got = shaders_law(inputs)[:, 0].astype(float)
    law = as_the_shaders_take_it(uniforms)
    for k, query in enumerate(inputs[0, :, :3].astype(float)):
        if reflectance["model"] == "hapke":
            exact, terms = hapke_50_digit(*query, law)
            bound = 8 * EPS32 * terms + LEAST_NORMAL32
        else:
            exact = lunar_lambert_50_digit(*query, law.albedo)
            bound = 16 * EPS32 * (exact + law.albedo)
        assert abs(got[k] - exact) <= bound, (query, got[k], exact)
