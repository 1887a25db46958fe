#version 430 core
// Tessellation evaluation shader (paper, Section 3): one "marching cubes" thread per vertex,
// i_c = D i_p + i, j_c = D j_p + j, k_c = k_p.
// The paper takes i = floor(l_h v + eps). An inner level of 1 is rounded up to 2 by OpenGL
// (quads), which adds vertices at u or v = 1/2; floor would map them onto cell 0 a second time.
// Rounding to the nearest integer and rejecting vertices that are not on the integer grid
// processes every cell exactly once.
layout(quads, equal_spacing, point_mode) in;

patch in ivec3 tc_patch;
patch in ivec2 tc_levels;
flat out ivec4 cell;          // j_c, i_c, k_c (column, row, slice), valid

uniform int patch_level;

void main() {
    float fj = float(tc_levels.x) * gl_TessCoord.x;
    float fi = float(tc_levels.y) * gl_TessCoord.y;
    int j = int(floor(fj + 0.5));
    int i = int(floor(fi + 0.5));
    bool ok = abs(fj - float(j)) < 0.25 && abs(fi - float(i)) < 0.25;
    int D = patch_level + 1;
    cell = ivec4(D * tc_patch.y + j, D * tc_patch.x + i, tc_patch.z, ok ? 1 : 0);
    gl_Position = vec4(0.0);
}
