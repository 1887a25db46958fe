// The voxel selection structures of the paper's Section 4, shared by every voxel method.
#pragma geoshade define BITS_PER_WORD
#pragma geoshade define UNIT_BITS
#pragma geoshade define UNIT_COLOR
#pragma geoshade define UNIT_PALETTE
// Layouts come from geoshade.render.layout (BITS_PER_WORD, UNIT_*).
uniform ivec3 box_size;                       // n, m, q: voxels of the box along x, y, z
layout(binding = UNIT_BITS) uniform usampler3D voxel_bits;     // R32UI, bit x%32 of word x/32
layout(binding = UNIT_COLOR) uniform usampler3D color_index;   // R8UI colour index map I
layout(binding = UNIT_PALETTE) uniform sampler2D palette;      // 256×1 RGBA8 palette A

bool selected(ivec3 p) {
    if (any(lessThan(p, ivec3(0))) || any(greaterThanEqual(p, box_size))) return false;
    uint w = texelFetch(voxel_bits, ivec3(p.x / BITS_PER_WORD, p.y, p.z), 0).r;
    return ((w >> uint(p.x % BITS_PER_WORD)) & 1u) != 0u;
}

vec4 voxel_color(ivec3 p) {
    uint idx = texelFetch(color_index, p, 0).r;
    return texelFetch(palette, ivec2(int(idx), 0), 0);
}

// face id 0..5 = +x +y +z -x -y -z  ->  object-space normal
vec3 face_normal_ocs(int f) {
    vec3 n = vec3(0.0);
    n[f % 3] = f < 3 ? 1.0 : -1.0;
    return n;
}
