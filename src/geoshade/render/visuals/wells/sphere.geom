#version 430 core
// A camera-facing square (two triangles) around each sphere; the fragment shader ray-casts it.
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
in vec4 v_sphere[];
in vec3 v_rgb[];
uniform mat4 proj;
uniform int ortho;
out vec3 f_pos;                 // view space, on the square
flat out vec4 f_sphere;
flat out vec3 f_rgb;

void main() {
    vec3 c = v_sphere[0].xyz;
    float r = v_sphere[0].w;
    if (r <= 0.0) return;
    // under perspective the silhouette is wider than r at the centre's depth: the tangent cone
    float d = length(c);
    // (x1.15 covers the elongation of off-axis silhouettes within a 40 degree field of view)
    float half_size = ortho != 0 ? r : (d > r ? 1.15 * r * d / sqrt(d * d - r * r) : 0.0);
    if (half_size <= 0.0) return;   // the eye is inside the sphere
    f_sphere = v_sphere[0];
    f_rgb = v_rgb[0];
    for (int q = 0; q < 4; ++q) {
        vec2 o = vec2(q & 1, q >> 1) * 2.0 - 1.0;
        f_pos = c + vec3(o * half_size, 0.0);
        gl_Position = proj * vec4(f_pos, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
