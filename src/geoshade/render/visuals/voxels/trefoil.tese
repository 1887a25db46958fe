#version 430 core
// Algorithm of generation of voxel threads, steps 7-8: one point per generated vertex.
#pragma geoshade define PATCH_L
layout(quads, equal_spacing, point_mode) in;

patch in ivec4 tc_patch;
patch in ivec2 tc_levels;
flat out ivec3 vox;

void main() {
    const float eps = 0.01;
    float fi = float(tc_levels.y) * gl_TessCoord.y;
    float fj = float(tc_levels.x) * gl_TessCoord.x;
    int i_v = int(floor(fi + eps));
    int j_v = int(floor(fj + eps));
    // x = j, y = i, z = k (paper's Algorithm of construction of visible trefoil, step 3)
    vox = ivec3((PATCH_L + 1) * tc_patch.y + j_v, (PATCH_L + 1) * tc_patch.x + i_v, tc_patch.z);
    // OpenGL treats an inner level of 1 as 2 when the other inner level is above 1, which adds
    // points at u or v = 1/2: the paper's floor(l u + eps) would map them onto voxel 0 again
    // (drawn twice). Points off the integer lattice get an index outside the box instead.
    if (abs(fi - round(fi)) > 0.25 || abs(fj - round(fj)) > 0.25) vox = ivec3(-1);
    gl_Position = vec4(0.0);
}
