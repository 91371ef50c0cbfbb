#version 330 core
// traj2events terrain shaded per pixel, fragment stage: the reflectance law at every pixel
// from the shading texture's normal and lit fraction times mu0, sampled over the pixel's
// footprint (render.lod.texture_filter), plus the light the terrain scattered there and
// earthshine;// depth along the boresight (m) as in terrain.frag.
in vec2 frag_uv;
in vec2 frag_uv_fine;
flat in float frag_layer;
flat in float frag_fine_layer;  // >= 0: the tile's layer of shading_fine, which it samples instead
in vec3 frag_to_camera_m;
in float frag_phase;
in float frag_scattered;

uniform sampler2DArray shading;  // per slot: normal xyz, lit fraction times mu0 (0..1)
uniform sampler2DArray shading_fine;  // the same one level finer, for tiles the camera magnifies
uniform float radiance_max;      // the law's maximum for this Sun (W m^-2 sr^-1)
uniform bool level_here;         // choose the texture's level here (footprint.py), not in the sampler
uniform float level_bias;        // log2 of the filter's width against the footprint (footprint.LOD_BIAS)

out vec4 frag_color;             // (radiance, depth, -, -): only R and G are stored

#include "reflectance.glsl"

const float MU_LIMB = 1e-4;      // cos(emission) of relief seen edge-on

void main()
{
    // Over the pixel's footprint: the mean normal, and the mean of lit * mu0 (footprint.py),
    // from the level whose texels match the footprint's size rho (texels per pixel): the
    // root mean square of its two sides, an isotropic filter as wide in variance as the
    // footprint (footprint.LOD_BIAS). Chosen here, not by the sampler: GPUs approximate
    // the footprint their own way (an NVIDIA H200's gave 18 % fewer events than llvmpipe's).
    // The texture one level finer where the tile has one (per tile: the same branch for
    // the whole triangle, so the derivatives below are its own).
    bool fine = frag_fine_layer >= 0.0;
    vec2 uv = fine ? frag_uv_fine : frag_uv;
    vec3 at = vec3(uv, fine ? frag_fine_layer : frag_layer);
    vec4 texel;
    if (level_here) {
        vec2 texels = vec2(fine ? textureSize(shading_fine, 0).xy : textureSize(shading, 0).xy);
        vec2 across = dFdx(uv) * texels, down = dFdy(uv) * texels;
        float rho2 = 0.5 * (dot(across, across) + dot(down, down));
        float level = 0.5 * log2(max(rho2, 1e-20)) + level_bias;
        texel = fine ? textureLod(shading_fine, at, level) : textureLod(shading, at, level);
    } else {  // anisotropic: the sampler's own footprint along its long axis
        texel = fine ? texture(shading_fine, at) : texture(shading, at);
    }
    vec3 normal = normalize(texel.xyz);
    // The triangle drawn here faces the camera; relief in its texture that faces away is
    // seen edge-on (its limb, mu -> 0), not black: a cut to 0 at mu = 0 flickered between
    // the limb's radiance and none as the view turned (docs/rendering.md "Seen edge-on").
    // Its incidence at least the footprint's mean lit mu0: a mean normal the Sun barely
    // lights over lit texels would make the law's 1 / (mu0 + mu) unbounded at the limb.
    float mu = max(dot(normal, normalize(frag_to_camera_m)), MU_LIMB);
    float mu0 = max(dot(normal, sun_dir), clamp(texel.w, 0.0, 1.0));
    float per_mu0 = law_per_mu0(mu0, mu, frag_phase);
    float direct = per_mu0 * clamp(texel.w, 0.0, 1.0) * irradiance / PI;
    float earthshine = earthshine_radiance(normal);
    float radiance = clamp(direct + frag_scattered + earthshine, 0.0, radiance_max);
    frag_color = vec4(radiance, 1.0 / gl_FragCoord.w, 0.0, 1.0);
}
