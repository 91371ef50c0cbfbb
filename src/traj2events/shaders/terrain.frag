#version 330 core
// traj2events terrain, fragment stage: radiance (W m^-2 sr^-1) times the lit fraction,
// and depth along the boresight (m), into a two-channel float32 buffer.
in vec3 frag_offset;
in float frag_radiance;
in float frag_lit;

uniform vec3 boresight;      // unit, camera +z (world)
uniform float radiance_max;  // the law's maximum for this Sun (W m^-2 sr^-1)

out vec4 frag_color;         // (radiance, depth, -, -): only R and G are stored

void main()
{
    // Interpolation at a pixel centre a hair outside a sliver triangle extrapolates; keep
    // the result within what the law can give (vertex values are in [0, radiance_max]).
    float radiance = clamp(frag_radiance * frag_lit, 0.0, radiance_max);
    frag_color = vec4(radiance, dot(frag_offset, boresight), 0.0, 1.0);
}
