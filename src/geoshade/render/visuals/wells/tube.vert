#version 430 core
// Well trajectory points (world coordinates minus the wells' origin).
in vec3 position;
uniform mat4 mv;
out vec3 v_pos;   // view space
void main() { v_pos = (mv * vec4(position, 1.0)).xyz; }
