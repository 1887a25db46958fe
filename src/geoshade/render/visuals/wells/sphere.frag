#version 430 core
// Ray-sphere intersection in view space: exact silhouette, normal and depth.
#include "phong.glsl"
in vec3 f_pos;
flat in vec4 f_sphere;
uniform mat4 proj;
uniform int ortho;
flat in vec3 f_rgb;
uniform int xray;           // 1: the pass of the parts hidden behind other geometry
out vec4 frag;

#include "xray.glsl"

void main() {
    if (xray_hole(xray)) discard;
    vec3 c = f_sphere.xyz;
    float r = f_sphere.w;
    vec3 ro = ortho != 0 ? vec3(f_pos.xy, c.z + 2.0 * r) : vec3(0.0);
    vec3 rd = ortho != 0 ? vec3(0.0, 0.0, -1.0) : normalize(f_pos);
    vec3 oc = ro - c;
    float b = dot(oc, rd);
    float h = b * b - (dot(oc, oc) - r * r);
    if (h < 0.0) discard;
    float t = -b - sqrt(h);
    vec3 p = ro + t * rd;
    vec4 clip = proj * vec4(p, 1.0);
    gl_FragDepth = clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
    frag = vec4(phong(xray_color(f_rgb, xray), (p - c) / r, p), 1.0);
}
