#version 330 core
// traj2events terrain, fragment stage: radiance (W m^-2 sr^-1) times the lit fraction plus
// the light scattered into shadows, and depth along the boresight (m), into a two-channel
// float32 buffer.
in float frag_radiance;
in float frag_lit;
in float frag_scattered;  // light scattered by the terrain, and earthshine (W m^-2 sr^-1)

uniform float radiance_max;  // the law's maximum for this Sun (W m^-2 sr^-1)

out vec4 frag_color;         // (radiance, depth, -, -): only R and G are stored

void main()
{
    // Interpolation at a pixel centre a hair outside a sliver triangle extrapolates; keep
    // the result within what the law can give (vertex values are in [0, radiance_max]).
    float radiance = frag_radiance * frag_lit + frag_scattered;
    // A NaN passes (clamp made it 0 on llvmpipe: a black pixel no check tells from shadow),
    // so that frames.h5's writer refuses the frame.
    radiance = isnan(radiance) ? radiance : clamp(radiance, 0.0, radiance_max);
    // Depth along the boresight is clip w (P's last row is (0, 0, -1, 0)); gl_FragCoord.w
    // holds its perspective-correct 1/w, so no per-vertex position has to be interpolated.
    frag_color = vec4(radiance, 1.0 / gl_FragCoord.w, 0.0, 1.0);
}
