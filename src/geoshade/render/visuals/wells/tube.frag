#version 430 core
// Cylinder look of the tube plane. TUBE_EXACT 1: the exact cylinder normal and the depth of the
// cylinder's surface (composes with other geometry); 0: the paper's normal
// normalize(r n1 + R (n1 x way)) and the plane's depth.
#pragma geoshade define TUBE_EXACT
#include "phong.glsl"
in vec3 f_pos;
in float f_r;
flat in vec3 f_side;
flat in vec3 f_way;
uniform mat4 proj;
uniform float radius;
flat in vec3 f_rgb;
uniform int xray;           // 1: the pass of the parts hidden behind other geometry
out vec4 frag;

#include "xray.glsl"

void main() {
    if (xray_hole(xray)) discard;
    vec3 e = cross(f_side, f_way);          // across the tube, towards or away from the viewer
    if (dot(e, e) < 1e-12) e = vec3(0.0, 0.0, 1.0);
    e = normalize(e);
    if (e.z < 0.0) e = -e;                  // towards the viewer (view space looks along -z)
    float r = clamp(f_r, -1.0, 1.0);
#if TUBE_EXACT
    vec3 n = r * f_side + sqrt(max(1.0 - r * r, 0.0)) * e;
    vec3 p = f_pos - r * radius * f_side + radius * n;   // point of the cylinder's surface
    vec4 clip = proj * vec4(p, 1.0);
    gl_FragDepth = clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
#else
    vec3 n = normalize(r * radius * f_side + radius * e);
#endif
    frag = vec4(phong(xray_color(f_rgb, xray), n, f_pos), 1.0);
}
