#version 330 core
// traj2events terrain, fragment stage: radiance (W m^-2 sr^-1) times the lit fraction,
// and depth along the boresight (m), into a two-channel float32 buffer.
in vec3 frag_offset;
in float frag_radiance;
in float frag_lit;

uniform vec3 boresight;      // unit, camera +z (world)

out vec4 frag_color;         // (radiance, depth, -, -): only R and G are stored

void main()
{
    frag_color = vec4(frag_radiance * frag_lit, dot(frag_offset, boresight), 0.0, 1.0);
}
