#version 330 core
// traj2events terrain: world position, normal and lit fraction to the fragment shader.
layout(location = 0) in vec3 position;
layout(location = NORMAL_LOC) in vec3 normal;
layout(location = TEXCOORD_0_LOC) in vec2 texcoord_0;   // x: lit fraction (0..1) from the horizon march
layout(location = INST_M_LOC) in mat4 inst_m;

uniform mat4 M;
uniform mat4 V;
uniform mat4 P;

out vec3 frag_offset;   // world position minus camera position (m), kept small for precision
out vec3 frag_normal;
out float frag_lit;
uniform vec3 cam_offset_from_origin;  // M's translation minus the camera position (m)

void main()
{
    vec4 local = inst_m * vec4(position, 1.0);
    frag_offset = mat3(M) * local.xyz + cam_offset_from_origin;
    frag_normal = normalize(mat3(M) * mat3(inst_m) * normal);
    frag_lit = texcoord_0.x;
    gl_Position = P * V * M * local;
}
