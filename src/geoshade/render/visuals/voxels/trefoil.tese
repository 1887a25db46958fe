#version 430 core
// Algorithm of generation of voxel threads, steps 7-8: one point per generated vertex.
#pragma geoshade define PATCH_L
layout(quads, equal_spacing, point_mode) in;

patch in ivec4 tc_patch;
patch in ivec2 tc_levels;
flat out ivec3 vox;

void main() {
    const float eps = 0.01;
    int i_v = int(floor(float(tc_levels.y) * gl_TessCoord.y + eps));
    int j_v = int(floor(float(tc_levels.x) * gl_TessCoord.x + eps));
    // x = j, y = i, z = k (paper's Algorithm of construction of visible trefoil, step 3)
    vox = ivec3((PATCH_L + 1) * tc_patch.y + j_v, (PATCH_L + 1) * tc_patch.x + i_v, tc_patch.z);
    gl_Position = vec4(0.0);
}
