#version 430 core
// Geometry shader (paper, Section 3): one "marching cubes" thread per cell. Classifies the
// cell (K), looks the triangles up in the table T (an integer 2D texture), places their
// vertices by Eq. (1) and emits them, with gradient normals (central differences of the field,
// interpolated along the edge like the position).
// Outside nodes (inactive, NaN, inf: stored below OUTSIDE_BELOW): by default a cell with one
// makes nothing, so the surface stays open there as at the grid's boundary; with caps on they
// count as below the level and the surface closes at the edges' midpoints.
#pragma geoshade define UNIT_FIELD
#pragma geoshade define UNIT_TABLE
#pragma geoshade define UNIT_POSITIONS
#pragma geoshade define UNIT_PROPERTY
#pragma geoshade define CORNER_OFFSETS
#pragma geoshade define EDGE_A
#pragma geoshade define EDGE_B
#pragma geoshade define OUTSIDE_BELOW
#pragma geoshade define MAX_VERTICES
layout(points) in;
layout(triangle_strip, max_vertices = MAX_VERTICES) out;

flat in ivec4 cell[];
out vec3 m_pos;               // model space: node index space, or local real coordinates
out vec3 m_normal;            // model space, towards lower values, not normalised
out float m_value;            // colour property (interpolated like the position)
flat out ivec2 m_id;          // linear cell index, triangle slot (for the capture)

uniform ivec3 cells;          // cells along x, y, z
uniform ivec3 patch_axes;     // field axes (0 x, 1 y, 2 z) of a patch's column, row, slice
uniform float level;          // S*
uniform mat4 mvp;
uniform int geometry_mode;    // 0: vertices in index space; 1: from the positions texture
uniform int color_mode;       // 0: none; 1: interpolate the property texture; 2: categories
                              // (one real code per triangle: its first vertex's nearest node)
uniform int caps;             // 0: open at outside nodes; 1: close the surface there
uniform ivec3 field_origin;   // node of the field (and property) textures' texel 0:
                              // a slab of slices when the field is marched in slabs
layout(binding = UNIT_FIELD) uniform sampler3D field;
layout(binding = UNIT_TABLE) uniform isampler2D table;
layout(binding = UNIT_POSITIONS) uniform sampler3D positions;
layout(binding = UNIT_PROPERTY) uniform sampler3D property;

const ivec3 CORNER[8] = CORNER_OFFSETS;
const int EA[12] = EDGE_A;
const int EB[12] = EDGE_B;

bool outside(float v) { return v <= OUTSIDE_BELOW; }

void main() {
    ivec3 c;
    c[patch_axes.x] = cell[0].x;
    c[patch_axes.y] = cell[0].y;
    c[patch_axes.z] = cell[0].z;
    if (cell[0].w == 0 || any(greaterThanEqual(c, cells))) return;
    float v[8];
    int K = 0;
    bool any_outside = false;
    for (int p = 0; p < 8; ++p) {
        v[p] = texelFetch(field, c + CORNER[p] - field_origin, 0).r;
        if (v[p] < level) K |= 1 << p;
        any_outside = any_outside || outside(v[p]);
    }
    if (K == 0 || K == 255 || (any_outside && caps == 0)) return;

    ivec3 nodes = cells + 1;
    vec3 P[8];
    vec3 g[8];
    float col[8];
    for (int p = 0; p < 8; ++p) {
        ivec3 q = c + CORNER[p];
        P[p] = geometry_mode == 0 ? vec3(q) : texelFetch(positions, q, 0).xyz;
        col[p] = color_mode != 0 ? texelFetch(property, q - field_origin, 0).r : 0.0;
        vec3 gr = vec3(0.0);
        float v0 = v[p];
        int bp = (K >> p) & 1;   // only the ends of crossed edges need a gradient
        bool used = bp != ((K >> (p ^ 1)) & 1) || bp != ((K >> (p ^ 2)) & 1)
                    || bp != ((K >> (p ^ 4)) & 1);
        if (used && !outside(v0)) {
            for (int a = 0; a < 3; ++a) {
                int bit = 1 << a;
                bool upper = (p & bit) != 0;
                ivec3 e = ivec3(a == 0 ? 1 : 0, a == 1 ? 1 : 0, a == 2 ? 1 : 0);
                ivec3 qo = upper ? q + e : q - e;
                bool out_ok = all(greaterThanEqual(qo, ivec3(0))) && all(lessThan(qo, nodes));
                float vo = out_ok ? texelFetch(field, qo - field_origin, 0).r : v0;
                if (outside(vo)) { vo = v0; out_ok = false; }
                float vi = v[p ^ bit];
                bool in_ok = !outside(vi);
                if (!in_ok) vi = v0;
                float span = float(int(in_ok) + int(out_ok));
                float d = upper ? vo - vi : vi - vo;
                gr[a] = span > 0.0 ? d / span : 0.0;
            }
        }
        g[p] = gr;
    }
    // normal = -J^{-T} grad, J = d(model position) / d(index); J^{-T} by cofactors (no division)
    vec3 cx = vec3(1.0, 0.0, 0.0), cy = vec3(0.0, 1.0, 0.0), cz = vec3(0.0, 0.0, 1.0);
    if (geometry_mode != 0) {
        cx = 0.25 * ((P[1] - P[0]) + (P[3] - P[2]) + (P[5] - P[4]) + (P[7] - P[6]));
        cy = 0.25 * ((P[2] - P[0]) + (P[3] - P[1]) + (P[6] - P[4]) + (P[7] - P[5]));
        cz = 0.25 * ((P[4] - P[0]) + (P[5] - P[1]) + (P[6] - P[2]) + (P[7] - P[3]));
    }
    float sgn = dot(cx, cross(cy, cz)) < 0.0 ? 1.0 : -1.0;
    mat3 cof = mat3(cross(cy, cz), cross(cz, cx), cross(cx, cy)) * sgn;

    int linear = (c.z * cells.y + c.y) * cells.x + c.x;
    for (int t = 0; t < MAX_VERTICES; t += 3) {
        if (texelFetch(table, ivec2(t, K), 0).r < 0) break;
        float code = 0.0;   // categories: codes are never blended into a code between them
        if (color_mode == 2) {
            int e0 = texelFetch(table, ivec2(t, K), 0).r;
            int a0 = EA[e0], b0 = EB[e0];
            float w0 = (outside(v[a0]) || outside(v[b0])) ? 0.5
                       : (level - v[a0]) / (v[b0] - v[a0]);
            code = w0 < 0.5 ? col[a0] : col[b0];
        }
        for (int s = 0; s < 3; ++s) {
            int e = texelFetch(table, ivec2(t + s, K), 0).r;
            int a = EA[e], b = EB[e];
            float va = v[a], vb = v[b];
            float w = (outside(va) || outside(vb)) ? 0.5 : (level - va) / (vb - va);   // Eq. (1)
            m_pos = P[a] + w * (P[b] - P[a]);
            m_normal = cof * (g[a] + w * (g[b] - g[a]));
            m_value = color_mode == 2 ? code : col[a] + w * (col[b] - col[a]);
            m_id = ivec2(linear, t / 3);
            gl_Position = mvp * vec4(m_pos, 1.0);
            EmitVertex();
        }
        EndPrimitive();
    }
}
