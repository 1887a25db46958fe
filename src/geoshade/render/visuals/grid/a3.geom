#version 430 core
// Approach 3: one face (A B C D) in, its two triangles out; colour from one byte per cell.
#pragma geoshade define UNIT_PALETTE
#pragma geoshade define UNIT_COLOR
layout(lines_adjacency) in;
layout(triangle_strip, max_vertices = 6) out;
#include "cpgrid.glsl"
#include "emit.glsl"
in vec3 v_pos[];
flat in uint v_cell[];
uniform int highlight;
layout(binding = UNIT_PALETTE) uniform sampler2D palette;
layout(binding = UNIT_COLOR) uniform usampler2D cell_colors;   // R8UI, one byte per cell

void main() {
    vec3 P[4] = vec3[4](v_pos[0], v_pos[1], v_pos[2], v_pos[3]);
    if (face_culled(P[0], P[1], P[2], P[3])) return;
    uint ci = texelFetch(cell_colors, lin2d(v_cell[0]), 0).r;
    emit_face(P, texelFetch(palette, ivec2(int(ci), 0), 0), float(highlight));
}
