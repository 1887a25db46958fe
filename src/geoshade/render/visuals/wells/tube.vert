#version 430 core
// Well trajectory points (world coordinates minus the wells' origin) and their tube's colour.
in vec3 position;
in vec3 rgb;
uniform mat4 mv;
out vec3 v_pos;   // view space
out vec3 v_rgb;
void main() {
    v_pos = (mv * vec4(position, 1.0)).xyz;
    v_rgb = rgb;
}
