#version 430 core
// Pass 1 of the stack ray caster (Graciano et al., Section 4.1): one ray per fragment of the
// box's back faces, in index space (x, y in columns, z in levels).
//  - bounding box entry/exit, clipped by the near/far planes and the cutting plane;
//  - WALK 0 (exact, geoshade's default): a 2D DDA over the columns (empty-space skipping at
//    column resolution: one index fetch per column crossed) and, in each column, the intervals
//    the ray passes through, each with its exact path length;
//    WALK 1 (the paper): coarse steps of one cell until a non-empty sample, one step back, then
//    fine steps at the Nyquist rate of the finest cell/interval;
//  - each stack walk starts at the top or the bottom of the stack (the box equator rule; WALK 0:
//    descending rays always walk down from the top, where they enter);
//  - front-to-back compositing with early ray termination;
//  - output: the transfer-function colour (premultiplied, unlit) and the depth of the first
//    contribution; shading is pass 2 (shade.frag).
#pragma geoshade define WALK
#pragma geoshade define UNIT_PALETTE
#pragma geoshade define UNIT_DRAPE
#pragma geoshade define UNIT_BRICKS
#pragma geoshade define UNIT_TOPS
#pragma geoshade define SSBO_DRAPE
#pragma geoshade define BRICK
#include "fetch.glsl"

layout(binding = UNIT_PALETTE) uniform sampler2D palette;  // RGBA8, alpha = opacity
layout(binding = UNIT_DRAPE) uniform sampler2D drape;      // image draped on the top surface
layout(binding = UNIT_BRICKS) uniform sampler2D brick_tops; // R32F: highest stack top of each
                                                            // BRICK × BRICK columns
uniform bool brick_skip;     // skip bricks of columns the ray passes above (beyond the paper)
uniform mat4 mv;
uniform mat4 proj;
uniform mat3 to_world;       // index space -> display world (linear part): path lengths
uniform vec3 eye_ocs;        // perspective: the eye in index space
uniform vec3 view_dir_ocs;   // orthographic: the viewing direction in index space
uniform bool ortho;
uniform vec2 near_far;
uniform vec4 section;        // keep dot(section.xyz, p) <= section.w (index space)
uniform bool section_on;
uniform bool boreholes_only;
uniform float ref_length;    // opacity a holds for this display path length
uniform int walk_from;       // 0: by the box equator (paper), 1: always top, 2: always bottom
uniform float coarse_len;    // WALK 1: coarse step (display length of one cell)
uniform vec3 nyquist;        // WALK 1: finest index-space feature per axis (1, 1, thinnest)
uniform bool drape_on;
uniform vec4 drape_rect;     // index-space x0, y0, width, height covered by the image
uniform float drape_mix;     // 1: image colour, 0: material colour
// pixels whose colour took something from the drape (the stats' ``drape``: never true for a
// picture that shows none)
layout(std430, binding = SSBO_DRAPE) buffer DrapeCount { uint drape_pixels; };
uniform int max_steps;
// smooth top (geoshade, for terrain: a DEM's heights are samples of a continuous surface): the
// top of the stacks is the bilinear interpolation of the column tops between column centres,
// not each column's flat top (WALK 0, stack layouts, descending rays); its shading normal is
// the bilinear interpolation of the central-difference gradients of the tops (np.gradient)
layout(binding = UNIT_TOPS) uniform sampler2D tops; // RG32F: column top (levels; < -1e29: none),
                                                    // highest top of the 3×3 columns around
uniform bool smooth_top;
uniform bool top_normals;    // write the smooth top's normal for the shading pass
uniform vec3 level_scale;    // display-world length of one index unit along x, y, z

in vec3 v_ocs;
layout(location = 0) out vec4 frag;
layout(location = 1) out vec4 frag_normal;  // xyz: display-world normal of a smooth top hit,
                                            // w = 1 (0: the shading pass uses hybrid normals)

const float OPAQUE = 1.0 - 1.0 / 512.0;   // early ray termination threshold (1 - eps)

vec3 ray_o;
vec3 ray_d;
float len_scale;     // display length per unit of t
vec4 acc = vec4(0.0);
bool hit = false;          // a contribution was made (t may be negative: orthographic rays)
float t_first = 0.0;
bool surf_piece = false;   // the piece being added starts on the smooth top surface
bool surf_first = false;   // the first contribution was such a piece
bool draped = false;       // a visible contribution took colour from the drape

#if WALK == 0 && LAYOUT != 6
const float NO_TOP = -1e29;

vec2 tops_at(ivec2 c) {
    return texelFetch(tops, clamp(c, ivec2(0), grid - 1), 0).rg;
}

// the heights at the four column centres of the dual cell with lower-left centre i0 + 0.5;
// a column without material takes the mean of the others (symmetric: the surface stays
// continuous across dual cells)
vec4 quad(vec4 h) {
    vec4 ok = vec4(greaterThan(h, vec4(NO_TOP)));
    float n = dot(ok, vec4(1.0));
    float m = n > 0.0 ? dot(ok * h, vec4(1.0)) / n : 0.0;
    return mix(vec4(m), h, ok);
}

vec4 quad_tops(ivec2 i0) {
    return quad(vec4(tops_at(i0).r, tops_at(i0 + ivec2(1, 0)).r, tops_at(i0 + ivec2(0, 1)).r,
                     tops_at(i0 + ivec2(1, 1)).r));
}

// the smooth top at index-space point p.xy (levels)
float surf_h(vec2 p) {
    vec2 q = p - 0.5;
    ivec2 i0 = ivec2(floor(q));
    vec2 f = q - vec2(i0);
    vec4 h = quad_tops(i0);
    return mix(mix(h.x, h.y, f.x), mix(h.z, h.w, f.x), f.y);
}

float gap(float t) {
    vec3 p = ray_o + t * ray_d;
    return p.z - surf_h(p.xy);
}

// first t in [ta, tb] where the ray is at or below the surface (one dual cell: the gap is a
// quadratic in t, fitted exactly through three points); tb + 1 when there is none
float piece_hit(float ta, float tb) {
    float g0 = gap(ta);
    if (g0 <= 0.0) return ta;
    if (!(tb > ta)) return tb + 1.0;
    float gm = gap(0.5 * (ta + tb));
    float g1 = gap(tb);
    float A = 2.0 * g0 - 4.0 * gm + 2.0 * g1;
    float B = -3.0 * g0 + 4.0 * gm - g1;
    float s = 2.0;
    if (abs(A) <= 1e-6 * (abs(B) + g0)) {
        if (B < 0.0) s = -g0 / B;
    } else {
        float disc = B * B - 4.0 * A * g0;
        if (disc >= 0.0) {
            float q = -0.5 * (B + (B >= 0.0 ? sqrt(disc) : -sqrt(disc)));
            float r1 = q / A;
            float r2 = q != 0.0 ? g0 / q : 2.0;
            float lo = min(r1, r2), hi = max(r1, r2);
            s = lo >= 0.0 ? lo : hi;
        }
    }
    return (s >= 0.0 && s <= 1.0) ? mix(ta, tb, s) : tb + 1.0;
}

// where a ray crossing column `cell` over [ta, tb] meets the smooth top: false when it stays
// above it; th = ta when it is already below it
bool surface_cross(ivec2 cell, float ta, float tb, out float th) {
    th = ta;
    vec2 c = vec2(cell) + 0.5;                 // the dual cells change on the centre lines
    float sx = abs(ray_d.x) > 1e-20 ? (c.x - ray_o.x) / ray_d.x : ta;
    float sy = abs(ray_d.y) > 1e-20 ? (c.y - ray_o.y) / ray_d.y : ta;
    float s1 = min(sx, sy), s2 = max(sx, sy);
    float e1 = (s1 > ta && s1 < tb) ? s1 : ta;
    float e2 = (s2 > ta && s2 < tb) ? s2 : tb;
    float h = piece_hit(ta, e1);
    if (h <= e1) { th = h; return true; }
    h = piece_hit(e1, e2);
    if (h <= e2) { th = h; return true; }
    h = piece_hit(e2, tb);
    if (h <= tb) { th = h; return true; }
    return false;
}

// central difference of the tops at column c along axis (one-sided at the border and next to
// a column without material, 0 without both neighbours), levels per column
vec2 grad_at(ivec2 c) {
    c = clamp(c, ivec2(0), grid - 1);
    float h = tops_at(c).r;
    vec2 g;
    for (int a = 0; a < 2; ++a) {
        ivec2 e = ivec2(a == 0, a == 1);
        bool has_m = c[a] > 0 && tops_at(c - e).r > NO_TOP;
        bool has_p = c[a] < grid[a] - 1 && tops_at(c + e).r > NO_TOP;
        float hm = has_m ? tops_at(c - e).r : h;
        float hp = has_p ? tops_at(c + e).r : h;
        g[a] = (has_m && has_p) ? 0.5 * (hp - hm) : (hp - hm);
    }
    return h > NO_TOP ? g : vec2(1e30);
}

vec2 mix_grad(vec2 a, vec2 b, vec2 c, vec2 d, vec2 f) {
    vec4 ok = vec4(a.x < 1e29, b.x < 1e29, c.x < 1e29, d.x < 1e29);
    float n = dot(ok, vec4(1.0));
    vec2 m = n > 0.0 ? (ok.x * a + ok.y * b + ok.z * c + ok.w * d) / n : vec2(0.0);
    a = ok.x > 0.0 ? a : m;
    b = ok.y > 0.0 ? b : m;
    c = ok.z > 0.0 ? c : m;
    d = ok.w > 0.0 ? d : m;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// display-world shading normal of the smooth top at index-space p.xy
vec3 surface_normal(vec2 p) {
    vec2 q = p - 0.5;
    ivec2 i0 = ivec2(floor(q));
    vec2 f = q - vec2(i0);
    vec2 g = mix_grad(grad_at(i0), grad_at(i0 + ivec2(1, 0)), grad_at(i0 + ivec2(0, 1)),
                      grad_at(i0 + ivec2(1, 1)), f);
    return normalize(vec3(-g.x / level_scale.x, -g.y / level_scale.y, 1.0 / level_scale.z));
}
#endif

// Composite one piece of material `pal` of display length `len` starting at ray parameter t.
// Returns true when the ray is opaque.
bool add(int pal, float len, float t, bool top_face) {
    if (pal <= 0 || !(len > 0.0)) return false;
    vec4 c = texelFetch(palette, ivec2(pal, 0), 0);
    if (c.a <= 0.0) return false;
    float a = c.a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - c.a, len / ref_length);
    vec3 rgb = c.rgb;
    if (drape_on && top_face) {
        vec3 p = ray_o + t * ray_d;
        vec2 uv = (p.xy - drape_rect.xy) / drape_rect.zw;
        if (all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)))) {
            vec4 im = texture(drape, uv);
            float w = drape_mix * im.a;
            rgb = mix(rgb, im.rgb, w);
            draped = draped || (w * a * (1.0 - acc.a) >= 1.0 / 255.0);
        }
    }
    if (!hit) {
        hit = true;
        t_first = t;
        surf_first = surf_piece;
    }
    acc.rgb += (1.0 - acc.a) * a * rgb;
    acc.a += (1.0 - acc.a) * a;
    return acc.a >= OPAQUE;
}

bool from_top(float z) {
    return walk_from == 1 || (walk_from == 0 && z > 0.5 * (zbox.x + zbox.y));
}

#if LAYOUT != 6
// Index of the interval holding z (count if z is above the stack), from the top or bottom.
int find(Stack s, ivec2 c, float z) {
    if (from_top(z)) {
        int i = s.count - 1;
        if (interval_at(s, c, i).y <= z) return s.count;
        while (i > 0 && interval_at(s, c, i - 1).y > z) --i;
        return i;
    }
    int i = 0;
    while (i < s.count && interval_at(s, c, i).y <= z) ++i;
    return i;
}

// Is interval i the top of its stack (nothing but air above)?
bool is_top(Stack s, ivec2 c, int i) {
    if (i >= s.count - 1) return true;
    vec2 n = interval_at(s, c, i + 1);
    return palette_index(n) == 0 && n.y >= zbox.y;
}

bool visible(Stack s) {
    return s.count > 0 && (!boreholes_only || s.flag);
}

// the palette index to draw for an interval (0: nothing; in borehole mode, logs only)
int shown(vec2 iv) {
    return boreholes_only && !from_log(iv) ? 0 : palette_index(iv);
}
#endif

#if LAYOUT == 6
// dense baseline: the palette index of voxel v (0: nothing; in borehole mode, logs only)
int voxel_at(ivec3 v) {
    uint r = texelFetch(dense_tex, v, 0).r;
    return boreholes_only && (r & 0x8000u) == 0u ? 0 : int(r & 0x7fffu);
}
#endif

#if WALK == 0 && LAYOUT != 6
// A 2D DDA over the columns, flattened into one loop: each iteration processes one interval of
// the current column (one interval fetch, one add) and, once the column is done or skipped,
// steps to the next column (or jumps over a brick of air) and reads its stack. A column's
// intervals are walked as pairs (interval i, end of interval i - 1), carrying the last fetch:
// descending rays walk down from the top of the stack (the first pair, the air above the top,
// tells whether the ray passes above the stack); ascending and horizontal rays start at the top
// or the bottom by the box equator rule (from_top), from the top by searching down to the
// interval that holds the entry height before walking up. A piece of a top face to drape stops
// the loop: its texture lookup runs after it, then the walk goes on. llvmpipe runs every branch
// of a loop body for all the pixels of a SIMD group until its slowest pixel leaves: one flat
// loop with one unit of work per iteration costs far less than nested loops.
void walk(float t0, float t1) {
    vec3 p0 = ray_o + t0 * ray_d;
    ivec2 cell = clamp(ivec2(floor(p0.xy)), ivec2(0), grid - 1);
    ivec2 stp = ivec2(greaterThanEqual(ray_d.xy, vec2(0.0))) * 2 - 1;
    ivec2 up = max(stp, ivec2(0));
    vec2 inv = vec2(stp) / max(abs(ray_d.xy), vec2(1e-20));
    vec2 t_next = (vec2(cell + up) - ray_o.xy) * inv;
    bool desc = ray_d.z < 0.0;
    bool level = ray_d.z == 0.0;
    float t = t0;
    float t_out = t0;
    ivec2 open_brick = ivec2(-1);
    bool in_col = false;       // walking the intervals of column `cell` between t and t_out
    bool advance = false;      // step to the next column before entering one
    Stack s = Stack(0, 0, false);
    float za = 0.0, zb = 0.0;  // the ray's heights entering and leaving the column
    int j = 0;                 // the interval fetched next
    bool down = true;          // pairs walk downwards (j decreasing)
    vec2 prev = vec2(0.0);     // the interval fetched last (down: the pair's interval)
    vec2 above = vec2(0.0);    // descending: the interval walked before (above) this pair's
    int k = 0;                 // columns visited and bricks jumped (the max_steps bound)
    bool pend = false;         // a piece of a top face to drape: pal, len, at t_pend
    bool sp_pend = false;
    bool col_smooth = false;   // smooth top in this column: its top interval ends at top_eff
    bool col_surf = false;     // the ray met the smooth top inside this column
    float ctop = 0.0, top_eff = 0.0;
    int pal_pend = 0;
    float len_pend = 0.0, t_pend = 0.0;
    for (;;) {
        while (in_col || k < max_steps) {
            if (!in_col) {
                if (advance) {
                    if (t_out >= t1) return;
                    if (t_next.x < t_next.y) {
                        cell.x += stp.x;
                        t = t_next.x;
                        t_next.x += abs(inv.x);
                    } else {
                        cell.y += stp.y;
                        t = t_next.y;
                        t_next.y += abs(inv.y);
                    }
                    if (any(lessThan(cell, ivec2(0))) || any(greaterThanEqual(cell, grid))) return;
                }
                ++k;
                advance = true;
                ivec2 b = cell / BRICK;
                if (brick_skip && b != open_brick) {
                    // the ray's lowest point inside this brick of columns; above its highest stack
                    // top the whole brick is air: jump to where the ray leaves it
                    ivec2 lo = b * BRICK;
                    ivec2 hi = min(lo + BRICK, grid);
                    vec2 t_out2 = (vec2(lo + up * (hi - lo)) - ray_o.xy) * inv;
                    float tb = min(min(t_out2.x, t_out2.y), t1);
                    float zmin = min(ray_o.z + t * ray_d.z, ray_o.z + tb * ray_d.z);
                    if (zmin >= texelFetch(brick_tops, b, 0).r) {
                        if (tb >= t1) return;
                        int axis = t_out2.x < t_out2.y ? 0 : 1;
                        t = tb;
                        ivec2 nc = clamp(ivec2(floor(ray_o.xy + t * ray_d.xy)), lo, hi - 1);
                        nc[axis] = stp[axis] > 0 ? hi[axis] : lo[axis] - 1;
                        if (any(lessThan(nc, ivec2(0))) || any(greaterThanEqual(nc, grid))) return;
                        cell = nc;
                        t_next = (vec2(cell + up) - ray_o.xy) * inv;
                        advance = false;
                        continue;
                    }
                    open_brick = b;
                }
                t_out = min(min(t_next.x, t_next.y), t1);
                if (!(t_out > t)) continue;
                s = stack_at(cell);
                if (!visible(s)) continue;
                za = ray_o.z + t * ray_d.z;
                zb = ray_o.z + t_out * ray_d.z;
                col_smooth = false;
                col_surf = false;
                if (smooth_top && desc) {
                    vec2 tp = tops_at(cell);
                    if (zb > tp.g) continue;      // above every top around: the surface too
                    float th;
                    if (!surface_cross(cell, t, t_out, th)) continue;
                    col_surf = th > t;
                    col_smooth = true;
                    t = th;
                    za = ray_o.z + t * ray_d.z;
                    ctop = tp.r;
                    top_eff = max(ctop, za);     // material up to the surface where it is higher
                }
                in_col = true;
                down = desc || from_top(za);
                j = down ? s.count - 1 : 0;
                prev = down ? vec2(0.0, 1e30) : vec2(0.0);   // down: the air above the stack
                above = prev;
            }
            // one pair: interval pi (iv) over [ylo, iv.y]
            vec2 nv = j >= 0 ? interval_at(s, cell, max(j, 0)) : vec2(0.0);
            if (col_smooth && j >= 0 && palette_index(nv) > 0 && nv.y == ctop) nv.y = top_eff;
            int pi = down ? j + 1 : j;
            vec2 iv = down ? prev : nv;
            float ylo = down ? nv.y : prev.y;
            bool search = down && !desc;          // down to the interval holding za, then up
            bool found = ylo <= za || j < 0;
            float z_a = desc ? min(za, iv.y) : max(za, ylo);
            float z_b = desc ? max(zb, ylo) : min(zb, iv.y);
            bool has = desc ? z_a > z_b : z_b > z_a;
            float ta = (z_a - ray_o.z) / ray_d.z;
            float tb = (z_b - ray_o.z) / ray_d.z;
            if (level) {                          // one interval, the one holding za
                has = down ? found : iv.y > za;
                ta = t;
                tb = t_out;
            }
            has = has && (!search || found);
            int pal = has ? shown(iv) : 0;
            float len = (tb - ta) * len_scale;
            // the top face of the stack's top interval, entered from above: drape it. The top
            // is the last interval, or the one under a filler (layouts 2-4 fill a column's
            // region with empty intervals up to the box top), as is_top() says
            bool top = pi >= s.count - 1 || (palette_index(above) == 0 && above.y >= zbox.y);
            bool sp = col_surf && has && pal > 0 && iv.y >= za;   // starts on the smooth top
            pend = drape_on && desc && pal > 0 && (col_smooth ? sp : (top && za >= iv.y));
            above = iv;
            surf_piece = sp;
            if (!pend && add(pal, len, ta, false)) return;
            bool last = down ? j < 0 : pi >= s.count - 1;
            if (desc) {
                in_col = !(last || ylo <= zb);
            } else if (level) {
                in_col = !(has || last);
            } else {
                in_col = !((!search || found) && (iv.y >= zb || pi >= s.count - 1));
            }
            if (search && found) {                // walk up from interval pi
                down = false;
                j += 2;
            } else {
                prev = nv;
                j += down ? -1 : 1;
            }
            if (pend) {
                pal_pend = pal;
                sp_pend = sp;
                len_pend = len;
                t_pend = ta;
                break;
            }
        }
        // the piece of a top face, with the drape
        if (!pend) return;
        pend = false;
        surf_piece = sp_pend;
        if (add(pal_pend, len_pend, t_pend, true)) return;
    }
}
#elif WALK == 0 && LAYOUT == 6
// Dense baseline: an exact 3D DDA over the voxels, the same compositing per voxel.

void walk(float t0, float t1) {
    ivec3 size = ivec3(grid, dense_levels);
    vec3 p0 = ray_o + t0 * ray_d;
    ivec3 v = clamp(ivec3(floor(p0)), ivec3(0), size - 1);
    ivec3 stp = ivec3(greaterThanEqual(ray_d, vec3(0.0))) * 2 - 1;
    vec3 inv = vec3(stp) / max(abs(ray_d), vec3(1e-20));
    vec3 t_next = (vec3(v + max(stp, ivec3(0))) - ray_o) * inv;
    float t = t0;
    for (int k = 0; k < max_steps; ++k) {
        float t_out = min(min(min(t_next.x, t_next.y), t_next.z), t1);
        if (t_out > t) {
            if (add(voxel_at(v), (t_out - t) * len_scale, t, false)) return;
        }
        if (t_out >= t1) return;
        if (t_next.x <= t_next.y && t_next.x <= t_next.z) {
            v.x += stp.x; t = t_next.x; t_next.x += abs(inv.x);
        } else if (t_next.y <= t_next.z) {
            v.y += stp.y; t = t_next.y; t_next.y += abs(inv.y);
        } else {
            v.z += stp.z; t = t_next.z; t_next.z += abs(inv.z);
        }
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, size))) return;
    }
}
#else
// WALK 1, the paper's sampling: material at a point (0 = nothing), and whether the point is
// within one fine step below the top surface of its column.
int sample_at(vec3 p, float z_tol, out bool top) {
    top = false;
#if LAYOUT == 6
    return voxel_at(clamp(ivec3(floor(p)), ivec3(0), ivec3(grid, dense_levels) - 1));
#else
    ivec2 c = clamp(ivec2(floor(p.xy)), ivec2(0), grid - 1);
    Stack s = stack_at(c);
    if (!visible(s)) return 0;
    int i = find(s, c, p.z);
    if (i >= s.count) return 0;
    vec2 iv = interval_at(s, c, i);
    top = drape_on && p.z >= iv.y - z_tol && is_top(s, c, i);
    return shown(iv);
#endif
}

void walk(float t0, float t1) {
    vec3 ad = max(abs(ray_d), vec3(1e-20));
    float dt_fine = 0.5 * min(min(nyquist.x / ad.x, nyquist.y / ad.y), nyquist.z / ad.z);
    float dt_coarse = max(coarse_len / len_scale, dt_fine);
    float z_tol = abs(ray_d.z) * dt_fine;
    bool fine = false;
    float t = t0;
    for (int k = 0; k < max_steps && t <= t1; ++k) {
        bool top;
        int pal = sample_at(ray_o + t * ray_d, z_tol, top);
        if (!fine) {
            if (pal > 0 && texelFetch(palette, ivec2(pal, 0), 0).a > 0.0) {
                fine = true;                      // a hit: one coarse step back, then fine
                t = max(t0, t - dt_coarse);
                continue;
            }
            t += dt_coarse;
        } else {
            if (add(pal, dt_fine * len_scale, t, top)) return;
            t += dt_fine;
        }
    }
}
#endif

void main() {
    ray_o = ortho ? v_ocs : eye_ocs;
    ray_d = ortho ? view_dir_ocs : v_ocs - eye_ocs;
    len_scale = length(to_world * ray_d);
    vec3 sgn = vec3(greaterThanEqual(ray_d, vec3(0.0))) * 2.0 - 1.0;
    vec3 inv = sgn / max(abs(ray_d), vec3(1e-20));   // finite 1/d
    vec3 box_lo = vec3(0.0, 0.0, zbox.x);
    vec3 box_hi = vec3(vec2(grid), zbox.y);
    vec3 ta = (box_lo - ray_o) * inv;
    vec3 tb = (box_hi - ray_o) * inv;
    vec3 t_lo = min(ta, tb);
    vec3 t_hi = max(ta, tb);
    float t0 = max(max(t_lo.x, t_lo.y), t_lo.z);
    float t1 = min(min(t_hi.x, t_hi.y), t_hi.z);

    // near and far planes: view-space z(t) = z0 + t dz must lie in [-far, -near]
    vec4 zrow = vec4(mv[0][2], mv[1][2], mv[2][2], mv[3][2]);
    float z0 = dot(zrow, vec4(ray_o, 1.0));
    float dz = dot(zrow.xyz, ray_d);
    if (dz >= 0.0) discard;
    t0 = max(t0, (-near_far.x - z0) / dz);
    t1 = min(t1, (-near_far.y - z0) / dz);

    // the cutting plane removes dot(n, p) > d
    if (section_on) {
        float s0 = dot(section.xyz, ray_o) - section.w;
        float sd = dot(section.xyz, ray_d);
        if (abs(sd) < 1e-20) {
            if (s0 > 0.0) discard;
        } else {
            float tc = -s0 / sd;
            if (sd > 0.0) t1 = min(t1, tc); else t0 = max(t0, tc);
        }
    }
    if (t0 >= t1) discard;
    walk(t0, t1);
    if (!hit) discard;
    vec4 clip = proj * (mv * vec4(ray_o + t_first * ray_d, 1.0));
    gl_FragDepth = clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
    frag = acc;
    if (draped) atomicAdd(drape_pixels, 1u);
    frag_normal = vec4(0.0);
#if WALK == 0 && LAYOUT != 6
    if (surf_first && top_normals)
        frag_normal = vec4(surface_normal((ray_o + t_first * ray_d).xy), 1.0);
#endif
}
