#version 430 core
// Phong shading of the isosurface (directional light), two-sided; colour by a property if set.
#pragma geoshade define UNIT_PALETTE
#include "phong.glsl"
in vec3 m_pos;
in vec3 m_normal;
in float m_value;
out vec4 frag;

uniform mat4 mv;
uniform mat3 normal_matrix;
uniform vec4 base_color;
uniform int color_mode;
uniform vec2 color_range;
uniform int ortho;            // 1: orthographic (view direction +z), 0: perspective
layout(binding = UNIT_PALETTE) uniform sampler2D palette;

void main() {
    vec3 p = (mv * vec4(m_pos, 1.0)).xyz;
    vec3 n = normal_matrix * m_normal;
    if (dot(n, n) < 1e-24) n = cross(dFdx(p), dFdy(p));    // flat field: the face normal
    vec3 to_eye = ortho != 0 ? vec3(0.0, 0.0, 1.0) : -p;
    if (dot(n, to_eye) < 0.0) n = -n;                       // two-sided lighting
    vec3 base = base_color.rgb;
    if (color_mode != 0) {
        float x = clamp((m_value - color_range.x) / max(color_range.y - color_range.x, 1e-30),
                        0.0, 1.0);
        base = texelFetch(palette, ivec2(int(x * 255.0 + 0.5), 0), 0).rgb;
    }
    frag = vec4(phong(base, n, p), 1.0);
}
