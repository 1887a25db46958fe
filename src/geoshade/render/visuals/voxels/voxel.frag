#version 430 core
// Phong shading of a voxel face with a directional light (all voxel methods).
#include "phong.glsl"
in vec3 f_pos;
flat in vec3 f_normal;
flat in vec4 f_color;
out vec4 frag;

void main() {
    frag = vec4(phong(f_color.rgb, f_normal, f_pos), 1.0);
}
