// traj2events: the reflectance laws of reflectance.py (the numpy reference the tests
// compare with), for the shader stages that evaluate them (renderer.glsl.expand_includes).
uniform vec3 sun_dir;        // unit, toward the Sun (world)
uniform float irradiance;    // W/m^2 at the Moon
uniform int model;           // 0 Hapke, 1 Lunar-Lambert
uniform float w;             // Hapke single-scattering albedo
uniform float hapke_r0;      // r0 of w (render.hapke_r0_float32): the same at every pixel
uniform float b;
uniform float c;
uniform float b0;
uniform float hw;            // opposition width h
uniform float albedo;        // Lunar-Lambert
uniform float bounce_albedo; // the law's bihemispherical albedo (reflectance.bihemispherical_albedo)
uniform vec3 earth_dir;      // unit, toward the Earth (world)
uniform float earth_irradiance;  // W/m^2 of earthshine on a surface facing the Earth (0: none)

const float PI = 3.14159265358979;

// Hapke's H function of the albedo w (its r0 from the uniform hapke_r0).
float chandrasekhar_h(float x)
{
    float log_term = x > 0.0 ? log((1.0 + x) / x) : 0.0;
    return 1.0 / (1.0 - w * x * (hapke_r0 + 0.5 * (1.0 - 2.0 * hapke_r0 * x) * log_term));
}

// One Henyey-Greenstein lobe in phase angle: peaks at g = 0 (backscatter) for b > 0. Its
// base a sum of positives (reflectance.henyey_greenstein: the textbook form cancels).
float hg(float b_, float cos_g)
{
    float a = abs(b_);
    float toward_peak = b_ >= 0.0 ? cos_g : -cos_g;
    float base = (1.0 - a) * (1.0 - a) + 2.0 * a * (1.0 - toward_peak);
    return (1.0 - a) * (1.0 + a) / (base * sqrt(base));  // not pow: exp2(1.5 log2 base), off 37 ulp at 1e-14
}

// Shadow hiding's B(g) = B0 / (1 + tan(g / 2) / h) (reflectance.opposition_surge: no
// division by zero, no tan near 180 deg).
float opposition_surge(float cos_g)
{
    float toward = hw * sqrt(1.0 + cos_g);
    return b0 * toward / (toward + sqrt(1.0 - cos_g));
}

// arccos(x), rad, within 2e-8 of it (Abramowitz & Stegun 4.4.46) plus float32's rounding:
// GLSL lets acos be 4096 ulp off (atan's bound), and llvmpipe's is 1.6e-4 rad off.
float arccos(float x)
{
    float t = abs(x);
    float p = -0.0012624911;
    p = p * t + 0.0066700901;
    p = p * t - 0.0170881256;
    p = p * t + 0.0308918810;
    p = p * t - 0.0501743046;
    p = p * t + 0.0889789874;
    p = p * t - 0.2145988016;
    p = p * t + 1.5707963050;
    float angle = sqrt(1.0 - t) * p;
    return x >= 0.0 ? angle : PI - angle;
}

// The part of the law that depends on the phase angle alone (Hapke: (1 + B(g)) P(g);
// Lunar-Lambert: L(g)): a coarse triangle's pixels can take it interpolated from its
// vertices, since it varies with directions only (terrain_textured.vert).
float phase_term(float cos_g)
{
    cos_g = clamp(cos_g, -1.0, 1.0);
    if (model == 0) {
        return (1.0 + opposition_surge(cos_g)) * (0.5 * (1.0 + c) * hg(b, cos_g) + 0.5 * (1.0 - c) * hg(-b, cos_g));
    }
    float g = degrees(arccos(cos_g));
    return clamp(1.0 - 0.019 * g + 2.42e-4 * g * g - 1.46e-6 * g * g * g, 0.0, 1.0);
}

// The reflectance factor per unit mu0 = cos(incidence), r_F / mu0, at the cosines mu0 >= 0
// and mu > 0 (emission), given phase_term of the phase angle. Both laws are mu0 times a
// factor smooth in mu0 (at mu0 <= 0 taken at 0): a pixel whose texels face the Sun
// differently takes the mean of lit * mu0 over its footprint times this factor
// (terrain_textured.frag), the law's linear part averaged exactly.
float law_per_mu0(float mu0, float mu, float phase)
{
    if (model == 0) {
        float multiple = chandrasekhar_h(mu0) * chandrasekhar_h(mu) - 1.0;
        return 0.25 * w / (mu0 + mu) * (phase + multiple);
    }
    return albedo * (2.0 * phase / (mu0 + mu) + (1.0 - phase));
}

// The same of a surface with unit normal n seen along unit to_camera (toward the camera)
// under sun_dir; 0 where the surface faces away from the camera.
float reflectance_per_mu0(vec3 n, vec3 to_camera, float phase)
{
    float mu = dot(n, to_camera);
    return mu > 0.0 ? law_per_mu0(max(dot(n, sun_dir), 0.0), mu, phase) : 0.0;
}

// Reflectance factor r_F (radiance = r_F * irradiance / PI) of a surface with unit normal
// n seen along unit to_camera under sun_dir, given phase_term of their phase angle; 0
// where either is below the surface's horizon.
float reflectance_factor_of_phase(vec3 n, vec3 to_camera, float phase)
{
    float mu0 = dot(n, sun_dir);
    return mu0 > 0.0 ? mu0 * reflectance_per_mu0(n, to_camera, phase) : 0.0;
}

float reflectance_factor(vec3 n, vec3 to_camera)
{
    return reflectance_factor_of_phase(n, to_camera, phase_term(dot(sun_dir, to_camera)));
}

// Reflectance factor of the sunlight the terrain scattered onto a point (scattering.py: S
// per unit of the Sun's irradiance and of the albedo): A S E_sun arrives, a Lambertian
// surface of albedo A returns A of it.
float scattered_factor(float scattered)
{
    return bounce_albedo * bounce_albedo * scattered;
}

// Earthshine off a surface with unit normal n (earthshine.py): Lambertian with the bounce
// albedo, not shadowed by the terrain (W m^-2 sr^-1).
float earthshine_radiance(vec3 n)
{
    return bounce_albedo * earth_irradiance * max(dot(n, earth_dir), 0.0) / PI;
}
