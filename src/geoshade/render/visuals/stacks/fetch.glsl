// Stack identification and iteration for the layouts of Section 4.2 (one per LAYOUT value):
// 1 textures, 2 r-supertexels, 3 l-supertexels, 4 texture3d, 5 ssbo, 6 the dense baseline.
// An interval is vec2(r, end): end = accumulated height (levels), r = ±(palette index + 1),
// negative for an interval of a borehole log; layouts 2-4 fill a column's region with
// (±1, box top), negative in a borehole column.
// The packing is geoshade.render.visuals.stacks.layouts.
#pragma geoshade define LAYOUT
#pragma geoshade define UNIT_INDEX
#pragma geoshade define UNIT_INTERVALS
#pragma geoshade define SSBO_INDEX
#pragma geoshade define SSBO_INTERVALS

struct Stack {
    int first;     // first interval (layouts 1, 5)
    int count;     // intervals to walk (0: nothing to draw)
    bool flag;     // borehole column
};

uniform ivec2 grid;        // columns along x, y
uniform vec2 zbox;         // lowest and highest level of the box
uniform int slots;         // layouts 2-4: intervals per column region
uniform ivec2 super_size;  // layout 2: supertexel width, height
uniform int iv_width;      // layout 1: width of the intervals texture

int palette_index(vec2 iv) { return int(abs(iv.x) + 0.5) - 1; }
bool from_log(vec2 iv) { return iv.x < 0.0; }

#if LAYOUT == 1
layout(binding = UNIT_INDEX) uniform usampler2D index_tex;       // RG32UI
layout(binding = UNIT_INTERVALS) uniform sampler2D interval_tex; // RG16F
Stack stack_at(ivec2 c) {
    uvec2 v = texelFetch(index_tex, c, 0).rg;
    return Stack(int(v.r), int(v.g & 0x7fffffffu), (v.g >> 31u) != 0u);
}
vec2 interval_at(Stack s, ivec2 c, int i) {
    int k = s.first + i;
    return texelFetch(interval_tex, ivec2(k % iv_width, k / iv_width), 0).rg;
}
#elif LAYOUT == 5
layout(std430, binding = SSBO_INDEX) readonly buffer StackIndex { uvec2 index_buf[]; };
layout(std430, binding = SSBO_INTERVALS) readonly buffer StackIntervals { uint interval_buf[]; };
Stack stack_at(ivec2 c) {
    uvec2 v = index_buf[c.x + grid.x * c.y];
    return Stack(int(v.x), int(v.y & 0x7fffffffu), (v.y >> 31u) != 0u);
}
vec2 interval_at(Stack s, ivec2 c, int i) {
    return unpackHalf2x16(interval_buf[s.first + i]);
}
#elif LAYOUT >= 2 && LAYOUT <= 4
#if LAYOUT == 4
layout(binding = UNIT_INTERVALS) uniform sampler3D interval_tex; // RG16F nx × ny × m
#else
layout(binding = UNIT_INTERVALS) uniform sampler2D interval_tex; // RG16F
#endif
vec2 interval_at(Stack s, ivec2 c, int i) {
#if LAYOUT == 2
    return texelFetch(interval_tex, c * super_size + ivec2(i % super_size.x, i / super_size.x),
                      0).rg;
#elif LAYOUT == 3
    return texelFetch(interval_tex, ivec2(c.x * slots + i, c.y), 0).rg;
#else
    return texelFetch(interval_tex, ivec3(c, i), 0).rg;
#endif
}
Stack stack_at(ivec2 c) {
    Stack s = Stack(0, slots, false);
    vec2 v0 = interval_at(s, c, 0);
    if (palette_index(v0) == 0 && v0.y >= zbox.y) return Stack(0, 0, false);  // no interval
    s.flag = interval_at(s, c, slots - 1).x < 0.0;  // a filler, or the (log's) top interval
    return s;
}
#elif LAYOUT == 6
layout(binding = UNIT_INTERVALS) uniform usampler3D dense_tex;   // R16UI, bit 15: log
uniform int dense_levels;
#endif
