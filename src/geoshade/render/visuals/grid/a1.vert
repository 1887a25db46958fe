#version 430 core
// Approach 1 (paper, Table 1): grid nodes packed in 8 bytes, x y z as uint16 in the local box
// (own buffer) and two colour indices (own buffer, so a new property re-uploads only them).
// Pass 0 draws the minus faces, coloured by colour 1 of their provoking node (i, j, k); pass 1
// the plus faces, coloured by colour 2 of node (i+1, j+1, k+1) (provoking vertex = first).
#pragma geoshade define UNIT_PALETTE
#pragma geoshade define A1_GS
#pragma geoshade define FAR_PX
in uvec3 pos_code;
in uvec2 colors;
uniform vec3 pos_lo;
uniform vec3 pos_step;
uniform int pass_index;
uniform int highlight;
uniform mat4 mv;
uniform mat4 proj;
layout(binding = UNIT_PALETTE) uniform sampler2D palette;
#if A1_GS
out vec3 v_pos;
flat out vec4 v_color;
#else
out vec3 f_pos;
noperspective out vec4 f_edge;
flat out vec4 f_color;
flat out float f_fade;
flat out float f_highlight;
#endif

void main() {
    vec4 pv = mv * vec4(pos_lo + vec3(pos_code) * pos_step, 1.0);
    uint ci = pass_index == 0 ? colors.x : colors.y;
    vec4 color = texelFetch(palette, ivec2(int(ci), 0), 0);
    gl_Position = proj * pv;
#if A1_GS
    v_pos = pv.xyz;
    v_color = color;
#else
    f_pos = pv.xyz;
    f_edge = vec4(FAR_PX);
    f_color = color;
    f_fade = 0.0;
    f_highlight = float(highlight);
#endif
}
