#version 430 core
// Sphere impostors (well markers and tube joints): centre (world minus origin), radius, colour.
in vec4 sphere;
in vec3 rgb;
uniform mat4 mv;
out vec4 v_sphere;   // view-space centre, radius
out vec3 v_rgb;
void main() {
    v_sphere = vec4((mv * vec4(sphere.xyz, 1.0)).xyz, sphere.w);
    v_rgb = rgb;
}
