#version 430 core
// Exact voxel ray caster: one ray per fragment of the box's back faces, a 3D DDA (Amanatides &
// Woo) over the voxels of the bit map that leaves, in one step, the largest empty cube the skip
// map proves empty around the current voxel (geoshade.compute.skipmap): the cube of bricks around
// an empty brick at brick distance k, an empty 4³ half-brick, an empty 2³ block, else the voxel.
// It draws the picture of the rasterised methods: Phong-lit unit cubes coloured
// palette[color_index], the face normal of the face the ray enters by, clipped at the near and
// far planes, and writes gl_FragDepth of the hit so that it composes with other geometry.
//
// Software rasterisers (llvmpipe) run both sides of every branch for all lanes of a SIMD group,
// masked, and a loop until its last lane leaves it: the loop body is one step (a voxel is a cube
// of side 1) and shading runs once, after the loop (docs/NOTES.md, core: the ray caster).
#pragma geoshade define BRICK
#pragma geoshade define UNIT_BRICKS
#include "voxel_common.glsl"
#include "phong.glsl"
#include "count.glsl"

#if BRICK != 8
#error "the skip map's 64-bit block masks need bricks of 8"
#endif
// RGB32UI per 8³ brick: 64-bit mask of its 2³ blocks (bit x2 + 4 y2 + 16 z2; .r holds z2 0-1,
// .g z2 2-3) and .b the Chebyshev distance in bricks to the nearest brick with a voxel
layout(binding = UNIT_BRICKS) uniform usampler3D bricks;
uniform mat4 mv;
uniform mat4 proj;
uniform mat3 normal_matrix;
uniform vec3 eye_ocs;        // perspective: the eye in index space
uniform vec3 view_dir_ocs;   // orthographic: the viewing direction in index space
uniform bool ortho;
uniform vec2 near_far;       // near and far plane distances in view space (in front: positive)
uniform bool brick_skip;     // empty-space skipping (off only for benchmarks and tests)
uniform ivec3 brick_offset;  // this box's first voxel in the index space of mv (bricks; else 0)
uniform mat4 inv_pmv;        // inverse of proj * mv: window -> index space
uniform vec4 viewport;       // x, y, width, height of the viewport

in vec3 v_ocs;
out vec4 frag;

int argmin3(vec3 t) {
    return t.x <= t.y ? (t.x <= t.z ? 0 : 2) : (t.y <= t.z ? 1 : 2);
}

int argmax3(vec3 t) {
    return t.x >= t.y ? (t.x >= t.z ? 0 : 2) : (t.y >= t.z ? 1 : 2);
}

// Shade voxel p (index space of mv) at the point hit on its face with object-space normal n_ocs.
void shade(ivec3 p, vec3 hit, vec3 n_ocs) {
    vec4 p_vcs = mv * vec4(hit, 1.0);
    vec4 clip = proj * p_vcs;
    gl_FragDepth = clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
    mark_seen(p - brick_offset);
    frag = vec4(phong(voxel_color(p - brick_offset).rgb, normal_matrix * n_ocs, p_vcs.xyz), 1.0);
}

// Make the other axes of voxel v agree with the DDA's own crossing times at time t (the voxel a
// pure DDA from the whole box's entry would be in), so that bricks and the whole box walk the same
// voxels: floor(o + t d) can round the other way where a ray passes near an edge.
ivec3 settle(ivec3 v, int axis, float t, vec3 o, vec3 inv, ivec3 s, ivec3 up) {
    for (int a = 0; a < 3; ++a) {
        if (a == axis) continue;
        float t_leave = (float(v[a] + up[a]) - o[a]) * inv[a];
        float t_enter = (float(v[a] + 1 - up[a]) - o[a]) * inv[a];
        if (t_leave <= t) v[a] += s[a];
        else if (t_enter > t) v[a] -= s[a];
    }
    return v;
}

void main() {
    // the ray o + t d in index space, from the pixel alone (not from the proxy point), so every
    // brick of a bricked box builds exactly the same ray as the whole box would
    vec2 ndc = (gl_FragCoord.xy - viewport.xy) / viewport.zw * 2.0 - 1.0;
    vec4 pa = inv_pmv * vec4(ndc, -1.0, 1.0);
    vec4 pb = inv_pmv * vec4(ndc, 1.0, 1.0);
    vec3 o = ortho ? pa.xyz / pa.w : eye_ocs;
    vec3 d = ortho ? view_dir_ocs : pb.xyz / pb.w - eye_ocs;
    ivec3 s = ivec3(greaterThanEqual(d, vec3(0.0))) * 2 - 1;         // DDA step per axis
    vec3 inv = vec3(s) / max(abs(d), vec3(1e-20));                     // finite 1/d

    // slab test with the box [brick_offset, brick_offset + box_size]
    ivec3 lo_box = brick_offset;
    ivec3 hi_box = brick_offset + box_size;
    vec3 ta = (vec3(lo_box) - o) * inv;
    vec3 tb = (vec3(hi_box) - o) * inv;
    vec3 t_lo = min(ta, tb);
    vec3 t_hi = max(ta, tb);
    float t_enter = max(max(t_lo.x, t_lo.y), t_lo.z);
    float t_exit = min(min(t_hi.x, t_hi.y), t_hi.z);

    // near and far planes: view-space z(t) = z0 + t dz must lie in [-far, -near]
    vec4 zrow = vec4(mv[0][2], mv[1][2], mv[2][2], mv[3][2]);
    float z0 = dot(zrow, vec4(o, 1.0));
    float dz = dot(zrow.xyz, d);
    if (dz >= 0.0) discard;
    float t_near = (-near_far.x - z0) / dz;
    float t_far = (-near_far.y - z0) / dz;
    bool from_near = t_near > t_enter;
    float t = max(t_enter, t_near);
    float t_end = min(t_exit, t_far);
    if (t >= t_end) discard;

    // first voxel: at the box entry face, or where the near plane cuts the ray
    ivec3 v = clamp(ivec3(floor(o + t * d)), lo_box, hi_box - 1);
    int axis = argmax3(t_lo);                  // the face the ray enters by
    ivec3 up = max(s, ivec3(0));               // 1 where the ray leaves a cell by its upper face
    if (!from_near) {
        v[axis] = s[axis] > 0 ? lo_box[axis] : hi_box[axis] - 1;
        v = clamp(settle(v, axis, t, o, inv, s, up), lo_box, hi_box - 1);
    }
    bool first = true;

    int max_steps = box_size.x + box_size.y + box_size.z + 3;
    ivec3 open_brick = ivec3(-1);              // the brick whose skip texel is in `skip`
    uvec3 skip = uvec3(0u);
    bool hit = false;
    for (int i = 0; i < max_steps; ++i) {
        ivec3 q = v - brick_offset;            // in this box: never negative here
        ivec3 b = q >> 3;
        if (b != open_brick) {
            skip = texelFetch(bricks, b, 0).rgb;
            open_brick = b;
        }
        // the side of the empty aligned cube around v: 8 (brick), 4, 2, or 1 (test the voxel)
        int side = 1;
        if (brick_skip) {
            ivec3 q4 = (q >> 2) & 1;
            ivec3 q2 = (q >> 1) & 3;
            uint w4 = q4.z == 0 ? skip.r : skip.g;
            uint w2 = q2.z < 2 ? skip.r : skip.g;
            if (skip.r == 0u && skip.g == 0u) side = 8;
            else if (((w4 >> uint(2 * q4.x + 8 * q4.y)) & 0x330033u) == 0u) side = 4;
            else if (((w2 >> uint(q2.x + 4 * q2.y + 16 * (q2.z & 1))) & 1u) == 0u) side = 2;
        }
        if (side == 1) {
            uint word = texelFetch(voxel_bits, ivec3(q.x / BITS_PER_WORD, q.y, q.z), 0).r;
            if (((word >> uint(q.x % BITS_PER_WORD)) & 1u) != 0u) {
                hit = true;
                break;
            }
        }
        // the cube to leave; an empty brick at distance k: the (2k-1)³ bricks around it
        ivec3 lo = (q & ~(side - 1)) + brick_offset;
        ivec3 hi = min(lo + side, hi_box);
        if (side == 8) {
            int k = int(skip.b) - 1;
            lo = max(lo - k * BRICK, lo_box);
            hi = min(hi + k * BRICK, hi_box);
        }
        // leave it by its far plane crossed first; the voxel there, settled on the other axes
        vec3 t_out = (vec3(lo + up * (hi - lo)) - o) * inv;
        axis = argmin3(t_out);
        t = t_out[axis];
        ivec3 w = clamp(ivec3(floor(o + t * d)), lo, hi - 1);
        w[axis] = s[axis] > 0 ? hi[axis] : lo[axis] - 1;
        v = settle(w, axis, t, o, inv, s, up);
        first = false;
        if (t >= t_end || any(lessThan(v, lo_box)) || any(greaterThanEqual(v, hi_box))) break;
    }
    if (!hit) discard;
    // one shading call (a branch on a software rasteriser runs both sides)
    vec3 n = vec3(0.0);
    float t_hit = t;
    if (first && from_near) {
        // a selected voxel cut by the near plane: its far face is seen from inside, as
        // the rasterised cubes draw it (outward normal, the voxel's own colour)
        vec3 t_next = (vec3(v + up) - o) * inv;
        int a = argmin3(t_next);
        n[a] = float(s[a]);
        t_hit = min(t_next[a], t_end);
    } else {
        n[axis] = -float(s[axis]);
    }
    shade(v, o + t_hit * d, n);
}
