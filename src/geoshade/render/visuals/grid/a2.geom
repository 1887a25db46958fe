#version 430 core
// Approach 2: the geometry shader builds the visible faces of a cell from COORD and ZCORN.
#pragma geoshade define FACE_CORNERS
#pragma geoshade define PAPER_MASK_ORDER
#pragma geoshade define A2_FAULT_SHIFT
#pragma geoshade define A2_MASK_SHIFT
#pragma geoshade define A2_COLOR_SHIFT
#pragma geoshade define UNIT_PALETTE
layout(points) in;
layout(triangle_strip, max_vertices = 36) out;   // 6 faces x 6 vertices x 17 components
#include "cpgrid.glsl"
#include "emit.glsl"
flat in uvec2 v_record[];
uniform mat4 mv;
layout(binding = UNIT_PALETTE) uniform sampler2D palette;
const int FC[24] = FACE_CORNERS;
const int ORDER[6] = PAPER_MASK_ORDER;

void main() {
    uint w = v_record[0].y;
    uint mask = (w >> A2_MASK_SHIFT) & 63u;
    uint fault = (w >> A2_FAULT_SHIFT) & 63u;
    vec4 color = texelFetch(palette, ivec2(int(w >> A2_COLOR_SHIFT), 0), 0);
    ivec3 cell = cell_of(v_record[0].x);
    vec3 P8[8];
    for (int c = 0; c < 8; ++c) {
        vec3 p = corner_at(cell, c, zcorn_at(zcorn_index(cell, c)));
        P8[c] = (mv * vec4(p, 1.0)).xyz;
    }
    for (int b = 0; b < 6; ++b) {
        if (((mask >> b) & 1u) == 0u) continue;
        int f = ORDER[b];
        vec3 P[4] = vec3[4](P8[FC[4 * f]], P8[FC[4 * f + 1]], P8[FC[4 * f + 2]],
                            P8[FC[4 * f + 3]]);
        if (face_culled(P[0], P[1], P[2], P[3])) continue;
        emit_face(P, color, float((fault >> b) & 1u));
    }
}
