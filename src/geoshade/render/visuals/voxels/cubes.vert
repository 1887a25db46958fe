#version 430 core
// Fixed-pipeline baseline: whole cubes in a vertex buffer, 36 vertices × 8 bytes per voxel:
// x, y, z (u16, box voxel corner) and face | colour_index << 8 (u16).
#pragma geoshade define UNIT_PALETTE
in uvec4 corner_face_color;
uniform mat4 mv;
uniform mat4 proj;
uniform mat3 normal_matrix;
layout(binding = UNIT_PALETTE) uniform sampler2D palette;
out vec3 f_pos;
flat out vec3 f_normal;
flat out vec4 f_color;

void main() {
    int f = int(corner_face_color.w & 255u);
    vec3 n = vec3(0.0);
    n[f % 3] = f < 3 ? 1.0 : -1.0;
    vec4 pv = mv * vec4(vec3(corner_face_color.xyz), 1.0);
    f_pos = pv.xyz;
    f_normal = normal_matrix * n;
    f_color = texelFetch(palette, ivec2(int(corner_face_color.w >> 8u), 0), 0);
    gl_Position = proj * pv;
}
