#version 430 core
// Sphere impostors (well markers and tube joints): centre (world minus origin) and radius.
in vec4 sphere;
uniform mat4 mv;
out vec4 v_sphere;   // view-space centre, radius
void main() { v_sphere = vec4((mv * vec4(sphere.xyz, 1.0)).xyz, sphere.w); }
