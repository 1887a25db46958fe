#version 430 core
// Tessellation control shader (paper, Section 3): tessellation levels l_w, l_h and the indices
// (i_p, j_p, k_p) of the patch in the 3D array of patches. Beyond the paper: a patch whose
// min/max node values cannot hold the level is discarded (levels 0) when skip_patches is on.
#pragma geoshade define UNIT_RANGES
layout(vertices = 1) out;

flat in int v_patch[];
patch out ivec3 tc_patch;     // i_p, j_p, k_p
patch out ivec2 tc_levels;    // l_w, l_h

uniform ivec3 patch_cells;    // n, m, q: cells along the patches' columns, rows and slices
uniform ivec3 patch_grid;     // n_p, m_p, q_p
uniform int patch_level;      // L_max; D = L_max + 1
uniform float level;          // S*
uniform int skip_patches;
uniform int patch_end;       // patches from patch_end on are not this draw's
layout(binding = UNIT_RANGES) uniform sampler3D patch_range;   // RG32F: min, max per patch

void main() {
    int g = v_patch[0];
    int n_p = patch_grid.x, m_p = patch_grid.y;
    int N = n_p * m_p;
    // the paper prints i_p = floor((g - N k_p) / M) with M = N q_p, a typo: the row of the
    // patch inside its slice is the quotient by the number of columns n_p
    int k_p = g / N;
    int i_p = (g - N * k_p) / n_p;
    int j_p = g - N * k_p - n_p * i_p;
    int D = patch_level + 1;
    bool on = g < patch_end;
    if (on && skip_patches != 0) {
        vec2 r = texelFetch(patch_range, ivec3(j_p, i_p, k_p), 0).rg;
        on = r.x < level && level <= r.y;
    }
    int l_w = max(min(patch_level, patch_cells.x - D * j_p - 1), 1);
    int l_h = max(min(patch_level, patch_cells.y - D * i_p - 1), 1);
    float fw = on ? float(l_w) : 0.0;   // level 0 discards the patch
    float fh = on ? float(l_h) : 0.0;
    gl_TessLevelInner[0] = fw;
    gl_TessLevelInner[1] = fh;
    gl_TessLevelOuter[0] = fh;
    gl_TessLevelOuter[1] = fw;
    gl_TessLevelOuter[2] = fh;
    gl_TessLevelOuter[3] = fw;
    tc_patch = ivec3(i_p, j_p, k_p);
    tc_levels = ivec2(l_w, l_h);
    gl_out[gl_InvocationID].gl_Position = vec4(0.0);
}
