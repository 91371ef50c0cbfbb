"""The reflectance laws at 50 digits (mpmath), as their sources write them, on the same
rounded inputs as the code they check: the numpy laws' searches (tests/scene) and the
shaders' (tests/renderer/test_law_uniforms.py)."""

from traj2events.scene.reflectance import ReflectanceParams


def lunar_lambert_50_digit(mu0: float, mu: float, cos_g: float, albedo: float) -> float:
    """McEwen's Lunar-Lambert law at 50 digits on the same (rounded) inputs."""
    import mpmath as mp

    with mp.workdps(50):
        mu0, mu, albedo = mp.mpf(mu0), mp.mpf(mu), mp.mpf(albedo)
        g = mp.degrees(mp.acos(max(min(mp.mpf(cos_g), 1), -1)))
        limb = min(max(1 - mp.mpf("0.019") * g + mp.mpf("2.42e-4") * g**2 - mp.mpf("1.46e-6") * g**3, 0), 1)
        return float(albedo * (2 * limb * mu0 / (mu0 + mu) + (1 - limb) * mu0))


def hapke_50_digit(mu0: float, mu: float, cos_g: float, p: ReflectanceParams) -> tuple[float, float]:
    """Hapke's law as the module docstring writes it (tan, arccos, the textbook lobes), at
    50 digits on the same rounded inputs: (I/F, the same with its bracket's terms summed
    before the -1: the scale of its rounding)."""
    import mpmath as mp

    with mp.workdps(50):
        mu0, mu, cos_g = mp.mpf(mu0), mp.mpf(mu), mp.mpf(cos_g)
        w, b, c = mp.mpf(p.single_scattering_albedo), mp.mpf(p.phase_b), mp.mpf(p.phase_c)
        r0 = (1 - mp.sqrt(1 - w)) / (1 + mp.sqrt(1 - w))

        def h_function(x):
            return 1 / (1 - w * x * (r0 + (1 - 2 * r0 * x) / 2 * mp.log((1 + x) / x)))

        def lobe(b_):
            return (1 - b_**2) / (1 - 2 * b_ * cos_g + b_**2) ** mp.mpf(1.5)

        surge = mp.mpf(p.opposition_b0) / (1 + mp.tan(mp.acos(cos_g) / 2) / mp.mpf(p.opposition_h))
        direct = (1 + surge) * ((1 + c) / 2 * lobe(b) + (1 - c) / 2 * lobe(-b))
        scale = w / 4 * mu0 / (mu0 + mu)
        multiple = h_function(mu0) * h_function(mu)
        return float(scale * (direct + multiple - 1)), float(scale * (direct + multiple))
