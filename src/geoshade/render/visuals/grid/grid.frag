#version 430 core
// Flat-lit cell faces with the paper's single-pass cell edges (all approaches).
#pragma geoshade define EDGE_QUAD
#pragma geoshade define EDGE_PAPER
#include "phong.glsl"
in vec3 f_pos;
noperspective in vec4 f_edge;
flat in vec4 f_color;
flat in float f_fade;
flat in float f_highlight;
uniform int edge_mode;
uniform float edge_width;       // line width in pixels
uniform vec4 edge_color;        // rgb, strength
uniform vec4 highlight_color;   // rgb, amount mixed into highlighted (fault) faces
out vec4 frag;

void main() {
    // the triangle's own normal, facing the viewer (same for every approach: same triangles)
    vec3 n = cross(dFdx(f_pos), dFdy(f_pos));
    if (dot(n, n) < 1e-30) n = vec3(0.0, 0.0, 1.0);
    vec3 base = mix(f_color.rgb, highlight_color.rgb, f_highlight * highlight_color.a);
    vec3 c = phong(base, n, f_pos);
    if (edge_mode != 0 && f_fade > 0.0) {
        float m;
        if (edge_mode == EDGE_PAPER) {
            // nearest edge: the diagonal (z) gives no line; else the nearer of the two sides
            float side = min(f_edge.x, f_edge.y);
            m = f_edge.z < side ? 1e6 : side;
        } else {
            m = min(min(f_edge.x, f_edge.y), min(f_edge.z, f_edge.w));
        }
        float half_w = 0.5 * edge_width;
        float line = 1.0 - smoothstep(half_w - 0.5, half_w + 0.5, m);
        c = mix(c, edge_color.rgb, line * edge_color.a * f_fade);
    }
    frag = vec4(c, 1.0);
}
