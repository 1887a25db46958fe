#version 430 core
// Pass 2 of the stack ray caster (deferred shading, Graciano et al. Section 4.1.2):
//  - hybrid image-space normals: a k×k×k grid of cells, axis-aligned in the model, centred on
//    the point p unprojected from this pixel's depth; a cell is occupied when its centre lies
//    behind the surface the depth buffer shows at the pixel it projects to (d' > d), and the
//    normal is the sum of the unit directions to the empty cells. The cell edge is the model's
//    smallest voxel edge, never smaller than one pixel at p (adaptive);
//  - Gaussian smoothing of the colour pass over the covered neighbour pixels;
//  - Lambert light, Eq. (1): I = i_a + k_d (L·N) i_d (i_d = 1);
//  - premultiplied output, blended over the target; the depth goes to the target's depth.
#pragma geoshade define UNIT_GCOLOR
#pragma geoshade define UNIT_GDEPTH
#pragma geoshade define UNIT_GNORMAL
#pragma geoshade define SHADE_LIGHT
#pragma geoshade define SHADE_SMOOTH
layout(binding = UNIT_GCOLOR) uniform sampler2D gcolor;
layout(binding = UNIT_GDEPTH) uniform sampler2D gdepth;
layout(binding = UNIT_GNORMAL) uniform sampler2D gnormal;  // a smooth top's normal (w = 1)
uniform mat3 view_rot;       // display world -> view space (rotation)
uniform mat4 proj;
uniform mat4 inv_proj;
uniform bool ortho;
uniform vec2 viewport;       // width, height in pixels
uniform int kernel;          // k of the k×k×k normal kernel (odd); < 3: no normals
uniform mat3 axes;           // the model's x, y, z axes in view space (unit columns)
uniform float voxel_len;     // smallest voxel edge in display units (view space)
uniform float sigma;         // Gaussian smoothing of the colours, pixels (SHADE_SMOOTH)
uniform vec3 light_dir;      // towards the light, view space (SHADE_LIGHT)
uniform vec4 material;       // ambient, diffuse, (specular, shininess: unused, Lambert only)
out vec4 frag;

vec3 view_pos(vec2 pix, float depth) {
    vec4 ndc = vec4(pix / viewport * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
    vec4 v = inv_proj * ndc;
    return v.xyz / v.w;
}

// view-space z (negative in front) of the surface the depth buffer shows at pixel px
float surface_z(ivec2 px) {
    float ndc = texelFetch(gdepth, px, 0).r * 2.0 - 1.0;
    return ortho ? (ndc - proj[3][2]) / proj[2][2] : -proj[3][2] / (ndc + proj[2][2]);
}

vec3 hybrid_normal(vec3 p) {
    float foot = 2.0 / (proj[1][1] * viewport.y) * (ortho ? 1.0 : -p.z);
    float s = max(voxel_len, foot);
    int r = kernel / 2;
    // the cell centres and their projections are affine in (i, j, k): step them
    vec3 ax = axes[0] * s, ay = axes[1] * s, az = axes[2] * s;
    vec4 c0 = proj * vec4(p, 1.0);
    vec4 cx = proj * vec4(ax, 0.0), cy = proj * vec4(ay, 0.0), cz = proj * vec4(az, 0.0);
    float tol = 0.25 * s;
    vec3 n = vec3(0.0);                       // in kernel (model axes) coordinates
    for (int k = -r; k <= r; ++k)
    for (int j = -r; j <= r; ++j)
    for (int i = -r; i <= r; ++i) {
        if (i == 0 && j == 0 && k == 0) continue;
        vec3 ijk = vec3(i, j, k);
        vec4 clip = c0 + ijk.x * cx + ijk.y * cy + ijk.z * cz;
        bool empty = true;
        if (clip.w > 0.0) {
            vec2 pix = (clip.xy / clip.w * 0.5 + 0.5) * viewport;
            if (all(greaterThanEqual(pix, vec2(0.0))) && all(lessThan(pix, viewport))) {
                float qz = p.z + ijk.x * ax.z + ijk.y * ay.z + ijk.z * az.z;
                empty = !(qz < surface_z(ivec2(pix)) - tol);   // d' > d: occupied
            }
        }
        if (empty) n += normalize(ijk);
    }
    n = axes * n;                             // axes is a rotation: normalize commutes
    return length(n) > 1e-6 ? normalize(n) : vec3(0.0, 0.0, 1.0);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(gcolor, px, 0);
    if (c.a <= 0.0) discard;
    float d = texelFetch(gdepth, px, 0).r;
#if SHADE_SMOOTH
    {
        int r = min(3, int(ceil(2.0 * sigma)));
        vec4 sum = vec4(0.0);
        ivec2 hi = ivec2(viewport) - 1;
        for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            vec4 cn = texelFetch(gcolor, clamp(px + ivec2(dx, dy), ivec2(0), hi), 0);
            if (cn.a > 0.0) sum += exp(-float(dx * dx + dy * dy) / (2.0 * sigma * sigma)) * cn;
        }
        c.rgb = sum.rgb / sum.a * c.a;       // alpha-weighted mean colour, own coverage
    }
#endif
    float light = 1.0;
#if SHADE_LIGHT
    vec4 gn = texelFetch(gnormal, px, 0);
    vec3 n = gn.w > 0.5 ? normalize(view_rot * gn.xyz)
           : kernel >= 3 ? hybrid_normal(view_pos(vec2(px) + 0.5, d)) : vec3(0.0, 0.0, 1.0);
    light = material.x + material.y * max(dot(n, normalize(light_dir)), 0.0);
#endif
    frag = vec4(clamp(c.rgb * light, 0.0, 1.0), c.a);
    gl_FragDepth = d;
}
