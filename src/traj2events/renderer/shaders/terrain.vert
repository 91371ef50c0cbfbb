#version 330 core
// traj2events terrain, vertex stage: the reflectance law per vertex (cells are a few
// pixels, so interpolating radiance across a triangle changes it by < 1e-3 and saves
// evaluating Hapke for every pixel), and positions relative to the camera. One instance
// per tile: its vertices are fetched from its slot of the shared vertex buffers.
// The laws: reflectance.glsl.
layout(location = 0) in vec4 tile;  // per instance (tile): xyz its origin minus the camera position (m), w its slot

uniform samplerBuffer vertex_position_lit;  // per vertex: position minus its tile's origin (m), lit fraction (0..1)
uniform samplerBuffer vertex_normal;        // per vertex: unit normal, scattered light S (scattering.py)
uniform int vertices_per_tile;              // a slot's vertices: every tile has the same grid and skirts
uniform mat4 V;            // the view rotation only (camera at the origin)
uniform mat4 P;

out float frag_radiance;
out float frag_lit;
out float frag_scattered;  // scattered light and earthshine (W m^-2 sr^-1)

#include "reflectance.glsl"

void main()
{
    int vertex = int(tile.w) * vertices_per_tile + gl_VertexID;
    vec4 position_lit = texelFetch(vertex_position_lit, vertex);
    // World position minus camera position (m), kept small for precision; tiles are only translated.
    vec3 offset = position_lit.xyz + tile.xyz;
    vec4 normal_scattered = texelFetch(vertex_normal, vertex);
    vec3 n = normalize(normal_scattered.xyz);
    vec3 to_camera = -normalize(offset);
    frag_radiance = reflectance_factor(n, to_camera) * irradiance / PI;
    frag_scattered = scattered_factor(normal_scattered.w) * irradiance / PI + earthshine_radiance(n);
    frag_lit = clamp(position_lit.w, 0.0, 1.0);  // from the horizon march
    gl_Position = P * V * vec4(offset, 1.0);
}
