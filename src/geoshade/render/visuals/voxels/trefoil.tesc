#version 430 core
// Algorithm of generation of voxel threads, steps 1-6 (paper, Section 4).
#pragma geoshade define PATCH_L
#pragma geoshade define BITS_PER_WORD
#pragma geoshade define UNIT_PATCH_BITS
layout(vertices = 1) out;

flat in int v_patch[];
patch out ivec4 tc_patch;     // i_p, j_p, k_p, valid
patch out ivec2 tc_levels;    // l_w, l_h

uniform ivec3 box_size;       // n, m, q
uniform ivec3 patch_grid;     // n_p, m_p, q_p
uniform int skip_empty;       // 1: skip patches whose patch bit is 0 (step 3)
layout(binding = UNIT_PATCH_BITS) uniform usampler3D patch_bits;

bool patch_bit(int jp, int ip, int kp) {
    uint w = texelFetch(patch_bits, ivec3(jp / BITS_PER_WORD, ip, kp), 0).r;
    return ((w >> uint(jp % BITS_PER_WORD)) & 1u) != 0u;
}

void main() {
    int id = v_patch[0];
    int n_p = patch_grid.x, m_p = patch_grid.y;
    int n_slice = n_p * m_p;
    int n_patches = n_slice * patch_grid.z;
    // step 2. The paper prints i_p = floor((id - k_p n_slice) / n_patches), a typo: the row of
    // the patch inside its slice is (id - k_p n_slice) / n_p.
    int k_p = id / n_slice;
    int i_p = (id - k_p * n_slice) / n_p;
    int j_p = id - k_p * n_slice - i_p * n_p;
    bool on = id < n_patches && (skip_empty == 0 || patch_bit(j_p, i_p, k_p));
    // step 4
    int l_w = max(min(PATCH_L, box_size.x - (PATCH_L + 1) * j_p - 1), 1);
    int l_h = max(min(PATCH_L, box_size.y - (PATCH_L + 1) * i_p - 1), 1);
    float fw = on ? float(l_w) : 0.0;   // level 0 discards the patch (step 3)
    float fh = on ? float(l_h) : 0.0;
    gl_TessLevelInner[0] = fw;
    gl_TessLevelInner[1] = fh;
    gl_TessLevelOuter[0] = fh;
    gl_TessLevelOuter[1] = fw;
    gl_TessLevelOuter[2] = fh;
    gl_TessLevelOuter[3] = fw;
    tc_patch = ivec4(i_p, j_p, k_p, on ? 1 : 0);
    tc_levels = ivec2(l_w, l_h);
    gl_out[gl_InvocationID].gl_Position = vec4(0.0);
}
