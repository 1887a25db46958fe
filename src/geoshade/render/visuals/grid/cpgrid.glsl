// Corner-point geometry on the GPU (approaches 2 and 3): COORD and ZCORN in linear 2D textures.
// Layouts come from geoshade.render.visuals.grid.layout (TEX_W, ZCORN_PER_TEXEL, UNIT_*).
#pragma geoshade define TEX_W
#pragma geoshade define ZCORN_PER_TEXEL
#pragma geoshade define UNIT_COORD
#pragma geoshade define UNIT_ZCORN
#pragma geoshade define ZCORN_BITS
uniform ivec3 dims;          // nx, ny, nz
uniform vec2 zdecode;        // 16 bits: local depth = zdecode.x + code * zdecode.y
layout(binding = UNIT_COORD) uniform sampler2D coord_tex;     // RGB32F, local coordinates
#if ZCORN_BITS == 16
layout(binding = UNIT_ZCORN) uniform usampler2D zcorn_tex;    // RGBA16UI, 4 codes per texel
#else
layout(binding = UNIT_ZCORN) uniform sampler2D zcorn_tex;     // RGBA32F, 4 local depths
#endif

ivec2 lin2d(uint idx) { return ivec2(int(idx % uint(TEX_W)), int(idx / uint(TEX_W))); }

float decode_z(uint code) { return zdecode.x + float(code) * zdecode.y; }

// the point of pillar (I, J) at local depth z (linear along the pillar; a flat pillar keeps x, y)
vec3 pillar_point(int I, int J, float z) {
    uint p = uint(I) + uint(dims.x + 1) * uint(J);
    vec3 top = texelFetch(coord_tex, lin2d(2u * p), 0).xyz;
    vec3 bot = texelFetch(coord_tex, lin2d(2u * p + 1u), 0).xyz;
    float dz = bot.z - top.z;
    float t = dz != 0.0 ? (z - top.z) / dz : 0.0;
    return vec3(top.xy + t * (bot.xy - top.xy), z);
}

// local depth of ZCORN value number idx (F order: (2i+a) + 2nx((2j+b) + 2ny(2k+c)))
float zcorn_at(uint idx) {
    uint t = idx / uint(ZCORN_PER_TEXEL);
    int c = int(idx % uint(ZCORN_PER_TEXEL));
#if ZCORN_BITS == 16
    return decode_z(texelFetch(zcorn_tex, lin2d(t), 0)[c]);
#else
    return texelFetch(zcorn_tex, lin2d(t), 0)[c];
#endif
}

uint zcorn_index(ivec3 cell, int corner) {
    uint x = uint(2 * cell.x + (corner & 1));
    uint y = uint(2 * cell.y + ((corner >> 1) & 1));
    uint z = uint(2 * cell.z + ((corner >> 2) & 1));
    return x + uint(2 * dims.x) * (y + uint(2 * dims.y) * z);
}

ivec3 cell_of(uint n) {
    uint nx = uint(dims.x), ny = uint(dims.y);
    return ivec3(int(n % nx), int((n / nx) % ny), int(n / (nx * ny)));
}

// corner c of cell (i, j, k) at a given local depth
vec3 corner_at(ivec3 cell, int corner, float z) {
    return pillar_point(cell.x + (corner & 1), cell.y + ((corner >> 1) & 1), z);
}
