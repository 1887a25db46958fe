// Emission of one cell face (quad A B C D, A-C the diagonal) from a geometry shader, with the
// paper's single-pass cell edges: screen-space distances to the face's edges are interpolated
// without perspective and turned into lines in grid.frag (smoothstep). The diagonal is never
// an edge. edge_mode EDGE_QUAD: one strip B A C D (triangles BAC, ACD) carrying the distances
// to the four quad edges; EDGE_PAPER: triangles ABC and CDA with the three heights of each
// (the diagonal's height is passed so the fragment can skip it, as the paper does).
#pragma geoshade define EDGE_QUAD
#pragma geoshade define EDGE_PAPER
#pragma geoshade define FAR_PX
uniform mat4 proj;
uniform vec2 viewport;        // pixels
uniform int edge_mode;        // 0 none, EDGE_QUAD, EDGE_PAPER
uniform vec2 edge_fade;       // on-screen face size (sqrt of its area, px): no edges below .x,
                              // full edges above .y (.y <= .x: no fading)
uniform float cull_sign;      // 0: draw all; else skip faces with cull_sign*dot(n, to_eye) < 0
uniform int ortho;

out vec3 f_pos;               // view space
noperspective out vec4 f_edge;
flat out vec4 f_color;
flat out float f_fade;
flat out float f_highlight;

vec2 to_px(vec4 clip) { return (clip.xy / clip.w * 0.5 + 0.5) * viewport; }

float line_dist(vec2 p, vec2 a, vec2 b) {
    vec2 d = b - a;
    float l = length(d);
    if (l < 1e-4) return FAR_PX;
    return abs(d.x * (p.y - a.y) - d.y * (p.x - a.x)) / l;
}

bool face_culled(vec3 A, vec3 B, vec3 C, vec3 D) {
    if (cull_sign == 0.0) return false;
    vec3 n = cross(C - A, D - B);
    vec3 to_eye = ortho != 0 ? vec3(0.0, 0.0, 1.0) : -(A + B + C + D) * 0.25;
    return cull_sign * dot(n, to_eye) < 0.0;
}

void put(vec3 p, vec4 clip, vec4 edge, vec4 color, float fade, float hl) {
    f_pos = p;
    f_edge = edge;
    f_color = color;
    f_fade = fade;
    f_highlight = hl;
    gl_Position = clip;
    EmitVertex();
}

float face_fade(vec2 d1, vec2 d2) {
    // on-screen size of a face = sqrt of its area from its diagonals (px)
    float size = sqrt(0.5 * abs(d1.x * d2.y - d1.y * d2.x));
    return edge_fade.y > edge_fade.x ? smoothstep(edge_fade.x, edge_fade.y, size) : 1.0;
}

// one triangle of the paper's scheme: vertices 0 -> 1 -> 2, the face diagonal is edge 2-0
void emit_paper_triangle(vec3 P0, vec3 P1, vec3 P2, vec4 c0, vec4 c1, vec4 c2,
                         vec2 s0, vec2 s1, vec2 s2, vec4 color, float fade, float hl) {
    put(P0, c0, vec4(line_dist(s0, s1, s2), 0.0, 0.0, FAR_PX), color, fade, hl);
    put(P1, c1, vec4(0.0, 0.0, line_dist(s1, s0, s2), FAR_PX), color, fade, hl);
    put(P2, c2, vec4(0.0, line_dist(s2, s0, s1), 0.0, FAR_PX), color, fade, hl);
    EndPrimitive();
}

// P: view-space corners A, B, C, D; emits 4 (quad strip) or 6 (paper) vertices
void emit_face(vec3 P[4], vec4 color, float hl) {
    vec4 clip[4];
    vec2 s[4];
    bool front = true;
    for (int v = 0; v < 4; ++v) {
        clip[v] = proj * vec4(P[v], 1.0);
        front = front && clip[v].w > 1e-6;
    }
    for (int v = 0; v < 4; ++v) s[v] = front ? to_px(clip[v]) : vec2(0.0);
    float fade = edge_mode != 0 && front ? face_fade(s[2] - s[0], s[3] - s[1]) : 0.0;
    if (edge_mode == EDGE_PAPER) {
        // triangles ABC and CDA (the paper prints DCA, whose diagonal is not its edge 2-0)
        emit_paper_triangle(P[0], P[1], P[2], clip[0], clip[1], clip[2], s[0], s[1], s[2],
                            color, fade, hl);
        emit_paper_triangle(P[2], P[3], P[0], clip[2], clip[3], clip[0], s[2], s[3], s[0],
                            color, fade, hl);
        return;
    }
    const int strip[4] = int[4](1, 0, 2, 3);   // B A C D: triangles BAC and ACD
    for (int q = 0; q < 4; ++q) {
        int v = strip[q];
        vec2 p = s[v];
        vec4 e = edge_mode == EDGE_QUAD
            ? vec4(line_dist(p, s[0], s[1]), line_dist(p, s[1], s[2]),
                   line_dist(p, s[2], s[3]), line_dist(p, s[3], s[0]))
            : vec4(FAR_PX);
        put(P[v], clip[v], e, color, fade, hl);
    }
    EndPrimitive();
}
