#version 450 core
// Ambient occlusion and a depth cue over a finished picture, from its depth buffer alone.
//
// Occlusion: around each pixel, pairs of opposite samples at 8 directions and two distances
// (half and all of `radius`, projected to pixels at the pixel's depth). The raw depth buffer
// is affine in screen space on a plane, so the mean of a pair's depths is the depth the chord
// between them has at this pixel: a pixel behind its chord lies in a crease and is darkened by
// how far behind it is (in `radius` units). Flat faces and convex edges are left as they are.
// Pairs with a background sample, and samples far in front (another surface crossing the
// view), do not count. Depth cue: the colour dims linearly with the view distance between the
// model's nearest and farthest points (`cue_range`).

uniform sampler2D color_tex;
uniform sampler2D depth_tex;
uniform mat4 proj;
uniform mat4 inv_proj;
uniform vec2 size;          // picture, pixels
uniform float radius;       // crease size, view-space units
uniform float strength;     // 0..1
uniform float depth_cue;    // 0..1
uniform vec2 cue_range;     // view distances of the model's nearest and farthest points

out vec4 frag;

const int DIRS = 8;
const float PI = 3.14159265358979;

vec3 view_pos(vec2 px, float d) {
    vec4 v = inv_proj * vec4(px / size * 2.0 - 1.0, d * 2.0 - 1.0, 1.0);
    return v.xyz / v.w;
}

float depth_at(vec2 px) {
    ivec2 q = clamp(ivec2(floor(px)), ivec2(0), ivec2(size) - 1);
    return texelFetch(depth_tex, q, 0).r;
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(color_tex, p, 0);
    float d = texelFetch(depth_tex, p, 0).r;
    if (d >= 1.0) {     // background
        frag = c;
        return;
    }
    vec2 pc = vec2(p) + 0.5;
    vec3 v = view_pos(pc, d);
    float z = -v.z;
    vec4 e = proj * vec4(v + vec3(radius, 0.0, 0.0), 1.0);
    float r_px = abs(e.x / e.w - (pc.x / size.x * 2.0 - 1.0)) * 0.5 * size.x;
    r_px = clamp(r_px, 1.5, 0.05 * max(size.x, size.y));
    float occ = 0.0;
    float n = 0.0;
    for (int ring = 1; ring <= 2; ++ring) {
        float rr = r_px * 0.5 * float(ring);
        float scale = radius * 0.5 * float(ring);
        for (int i = 0; i < DIRS; ++i) {
            float a = (float(i) + 0.5 * float(ring - 1)) * PI / float(DIRS);
            vec2 o = vec2(cos(a), sin(a)) * rr;
            float da = depth_at(pc + o);
            float db = depth_at(pc - o);
            n += 1.0;
            if (da >= 1.0 || db >= 1.0) {
                continue;
            }
            float zm = -view_pos(pc, 0.5 * (da + db)).z;
            float za = -view_pos(pc + o, da).z;
            float zb = -view_pos(pc - o, db).z;
            float front = max(z - za, z - zb);
            float w = clamp((z - zm) / scale - 0.02, 0.0, 1.0);
            occ += w * (1.0 - smoothstep(2.0 * scale, 4.0 * scale, front));
        }
    }
    float ao = 1.0 - strength * occ / max(n, 1.0);
    float span = max(cue_range.y - cue_range.x, 1e-30);
    float cue = 1.0 - depth_cue * clamp((z - cue_range.x) / span, 0.0, 1.0);
    frag = vec4(c.rgb * ao * cue, c.a);
}
