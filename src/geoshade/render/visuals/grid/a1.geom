#version 430 core
// Approach 1 with cell edges: the triangles of a face arrive as ABC, ACD (A = provoking node);
// the second is re-ordered to CDA so that in both the face diagonal is edge 2-0 (paper).
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
#include "emit.glsl"
in vec3 v_pos[];
flat in vec4 v_color[];
uniform int highlight;

void main() {
    int o0 = 0, o1 = 1, o2 = 2;
    if ((gl_PrimitiveIDIn & 1) == 1) { o0 = 1; o1 = 2; o2 = 0; }
    vec4 c0 = gl_in[o0].gl_Position, c1 = gl_in[o1].gl_Position, c2 = gl_in[o2].gl_Position;
    bool front = c0.w > 1e-6 && c1.w > 1e-6 && c2.w > 1e-6;
    vec2 s0 = front ? to_px(c0) : vec2(0.0);
    vec2 s1 = front ? to_px(c1) : vec2(0.0);
    vec2 s2 = front ? to_px(c2) : vec2(0.0);
    // face size from the triangle: twice its area is the area of the face's parallelogram
    vec2 e1 = s1 - s0, e2 = s2 - s0;
    float size = sqrt(abs(e1.x * e2.y - e1.y * e2.x));
    float fade = edge_mode != 0 && front
        ? (edge_fade.y > edge_fade.x ? smoothstep(edge_fade.x, edge_fade.y, size) : 1.0) : 0.0;
    emit_paper_triangle(v_pos[o0], v_pos[o1], v_pos[o2], c0, c1, c2, s0, s1, s2,
                        v_color[0], fade, float(highlight));
}
