#version 430 core
// Approach 3, faces storage: the corners of the face from its pillars and stored depths.
#pragma geoshade define FACE_CORNERS
#pragma geoshade define A3F_FACE_BITS
#pragma geoshade define UNIT_PALETTE
layout(points) in;
layout(triangle_strip, max_vertices = 6) out;
#include "cpgrid.glsl"
#include "emit.glsl"
flat in uint v_head[];
flat in vec4 v_z[];
flat in uint v_color[];
uniform mat4 mv;
uniform int highlight;
uniform uint cell_base;  // the draw range's first cell number (a multiple of 2^29)
layout(binding = UNIT_PALETTE) uniform sampler2D palette;
const int FC[24] = FACE_CORNERS;

void main() {
    uint head = v_head[0];
    int f = int(head & ((1u << A3F_FACE_BITS) - 1u));
    ivec3 cell = cell_of(cell_base + (head >> A3F_FACE_BITS));
    vec3 P[4];
    for (int v = 0; v < 4; ++v)
        P[v] = (mv * vec4(corner_at(cell, FC[4 * f + v], v_z[0][v]), 1.0)).xyz;
    if (face_culled(P[0], P[1], P[2], P[3])) return;
    emit_face(P, texelFetch(palette, ivec2(int(v_color[0]), 0), 0), float(highlight));
}
