#version 330 core
// traj2events terrain shaded per pixel, vertex stage: coarse tiles whose normals and lit
// fractions come from a texture of finer levels (render.lod.shading_levels > 0). Here:
// positions relative to the camera and where each vertex sits in its tile's shading
// texture (the law, per pixel: terrain_textured.frag).
layout(location = 0) in vec4 tile;  // per instance (tile): xyz its origin minus the camera position (m), w its slot
layout(location = 1) in vec2 uv;    // per vertex of a tile: its place in the tile's shading texture
layout(location = 2) in vec4 fine_slots;  // per instance: the slots of its texture one level finer, or -1

uniform samplerBuffer vertex_position_lit;  // per vertex: position minus its tile's origin (m), scattered light S
                                            // (scattering.py; lit comes from the texture here)
uniform int vertices_per_tile;
uniform mat4 V;            // the view rotation only (camera at the origin)
uniform mat4 P;

out vec2 frag_uv;
flat out float frag_layer;  // the tile's slot: its layer of the shading texture array
flat out vec4 frag_fine_slots;
out vec3 frag_to_camera_m;
out float frag_scattered;   // light scattered into shadows by the terrain (W m^-2 sr^-1)

#include "reflectance.glsl"

void main()
{
    vec4 position_scattered = texelFetch(vertex_position_lit, int(tile.w) * vertices_per_tile + gl_VertexID);
    vec3 offset = position_scattered.xyz + tile.xyz;
    frag_scattered = scattered_factor(position_scattered.w) * irradiance / PI;
    frag_uv = uv;
    frag_layer = tile.w;
    frag_fine_slots = fine_slots;
    frag_to_camera_m = -offset;
    gl_Position = P * V * vec4(offset, 1.0);
}
