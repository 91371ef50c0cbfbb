#version 330 core
// traj2events terrain shaded per pixel, fragment stage: the reflectance law at every pixel
// from the shading texture's normal and lit fraction times mu0, sampled over the pixel's
// footprint (render.lod.texture_filter), plus the light the terrain scattered there and
// earthshine; depth along the boresight (m) as in terrain.frag. No branches on options:
// llvmpipe runs both sides of a branch, even on a uniform (a second read here cost 14 %).
in vec2 frag_uv;
flat in float frag_layer;
flat in vec4 frag_fine_slots;   // >= 0: the layers of the tile's texture one level finer, by quarter
in vec3 frag_to_camera_m;
in float frag_scattered;

uniform sampler2DArray shading;  // per slot: normal xyz, lit fraction times mu0 (0..1)
uniform float radiance_max;      // the law's maximum for this Sun (W m^-2 sr^-1)

out vec4 frag_color;             // (radiance, depth, -, -): only R and G are stored

#include "reflectance.glsl"
#include "footprint.glsl"

const float MU_LIMB = 1e-4;      // cos(emission) of relief seen edge-on

void main()
{
    // Over the pixel's footprint: the mean normal, and the mean of lit * mu0 (footprint.py,
    // footprint.glsl). Where the tile has its texture one level finer (magnified texels),
    // that one, held as four quarters that share their middle texels: the texel coordinates
    // run on across them (so do their derivatives), and the reads take the quarter's layer.
    bool fine = frag_fine_slots.x >= 0.0;
    vec2 texel_at = (frag_uv * texture_side - 0.5) * (fine ? 2.0 : 1.0);
    vec2 quarter = fine ? step(vec2(texture_side - 1.0), texel_at) : vec2(0.0);
    float layer = fine ? frag_fine_slots[int(quarter.y) * 2 + int(quarter.x)] : frag_layer;
    // The footprint's sides (texels per pixel): the derivatives at the pixel's centre.
    // dFdx(texel_at) differences it with the quad's other pixel, which next to the horizon
    // lies beyond the triangle's vanishing line (a box a whole tile wide). texel_at times
    // gl_FragCoord.w (1 / w) is linear on the screen, so its differences are exact, and
    // d(A / B) = (dA - (A / B) dB) / B.
    vec2 texel_over_w = texel_at * gl_FragCoord.w;
    vec2 across = (dFdx(texel_over_w) - texel_at * dFdx(gl_FragCoord.w)) / gl_FragCoord.w;
    vec2 down = (dFdy(texel_over_w) - texel_at * dFdy(gl_FragCoord.w)) / gl_FragCoord.w;
    // The box centred on the pixel and inside its layer: one over the edge read the edge
    // texel of its level for the ground beyond, a mean from inside the tile (12 % bright at
    // the horizon under a grazing Sun; docs/decisions/0015-footprint-at-edges.md).
    vec2 local = texel_at - quarter * (texture_side - 1.0);
    vec2 room = 2.0 * max(min(local + 0.5, texture_side - 0.5 - local), 0.0);
    vec2 keep = min(room / max(sqrt(across * across + down * down), 1e-30), 1.0);
    across *= keep;
    down *= keep;
    vec4 texel = footprint_mean(shading, local, layer, across, down);
    vec3 normal = normalize(texel.xyz);
    // The triangle drawn here faces the camera; relief in its texture that faces away is
    // seen edge-on (its limb, mu -> 0), not black: a cut to 0 at mu = 0 flickered between
    // the limb's radiance and none as the view turned (docs/rendering.md "Seen edge-on").
    // Its incidence at least the footprint's mean lit mu0: a mean normal the Sun barely
    // lights over lit texels would make the law's 1 / (mu0 + mu) unbounded at the limb.
    float mu = max(dot(normal, normalize(frag_to_camera_m)), MU_LIMB);
    float mu0 = max(dot(normal, sun_dir), clamp(texel.w, 0.0, 1.0));
    // The phase term per pixel too: interpolated from the vertices, it was 3.6 % off in a
    // column 2 m above cells of several pixels (docs/decisions/0014-phase-per-pixel.md).
    float per_mu0 = law_per_mu0(mu0, mu, phase_term(dot(sun_dir, normalize(frag_to_camera_m))));
    float direct = per_mu0 * clamp(texel.w, 0.0, 1.0) * irradiance / PI;
    float earthshine = earthshine_radiance(normal);
    float radiance = direct + frag_scattered + earthshine;
    // A NaN passes (clamp made it 0 on llvmpipe: a black pixel no check tells from shadow),
    // so that frames.h5's writer refuses the frame.
    radiance = isnan(radiance) ? radiance : clamp(radiance, 0.0, radiance_max);
    frag_color = vec4(radiance, 1.0 / gl_FragCoord.w, 0.0, 1.0);
}
