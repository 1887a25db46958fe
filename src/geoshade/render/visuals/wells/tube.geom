#version 430 core
// The paper's 3D tube impostor: one segment a1-a2 of a trajectory from four points a0 a1 a2 a3
// (lines_adjacency), a plane in view space whose corners C1..C4 are the intersections of the
// segments' offset lines (mitre joins); the fragment shader gives it the look of a cylinder.
layout(lines_adjacency) in;
layout(triangle_strip, max_vertices = 4) out;
in vec3 v_pos[];
in vec3 v_rgb[];
uniform mat4 proj;
uniform float radius;
out vec3 f_pos;            // view space, on the plane through the axis
out float f_r;             // signed lateral offset in units of the radius (-1 .. 1)
flat out vec3 f_side;      // n1 (view space, in the screen plane)
flat out vec3 f_way;       // segment direction (view space)
flat out vec3 f_rgb;       // the segment's colour (its first point's)

// intersection of the lines p1 + t d1 and p2 + s d2 (the paper's `intersect`); falls back to
// p_fallback where the lines are (nearly) parallel or the mitre is longer than 2 radii
vec2 intersect(vec2 p1, vec2 d1, vec2 p2, vec2 d2, vec2 fallback) {
    float den = d1.x * d2.y - d1.y * d2.x;
    if (abs(den) < 1e-4) return fallback;
    float t1 = (p1.x * d2.y - p1.y * d2.x - p2.x * d2.y + p2.y * d2.x) / den;
    vec2 c = p1 - t1 * d1;
    return distance(c, fallback) > 2.0 * radius ? fallback : c;
}

vec2 dir2(vec2 a, vec2 b, vec2 alt) {
    vec2 d = a - b;
    return dot(d, d) > 1e-12 ? normalize(d) : alt;
}

void corner(vec2 xy, float z, float r) {
    f_pos = vec3(xy, z);
    f_r = r;
    gl_Position = proj * vec4(f_pos, 1.0);
    EmitVertex();
}

void main() {
    vec3 a0 = v_pos[0], a1 = v_pos[1], a2 = v_pos[2], a3 = v_pos[3];
    vec2 d12 = a1.xy - a2.xy;
    // a segment along the line of sight covers no area: the joint spheres show it
    if (dot(d12, d12) < 1e-10 * max(dot(a1, a1), 1.0)) return;
    vec3 way = normalize(a1 - a2);                       // step 2
    vec2 v1 = normalize(d12);                            // step 3
    vec2 v0 = dir2(a0.xy, a1.xy, v1);
    vec2 v2 = dir2(a2.xy, a3.xy, v1);
    vec2 n0 = vec2(v0.y, -v0.x), n1 = vec2(v1.y, -v1.x), n2 = vec2(v2.y, -v2.x);  // step 4
    float R = radius;
    // step 5 (the paper's intersect returns p1 + t1 d1 with t1 as printed, measured along -d1
    // from p1 for its sign convention; written here as p1 - t1 d1 with the same t1)
    vec2 C1 = intersect(a0.xy - n0 * R, v0, a2.xy - n1 * R, v1, a1.xy - n1 * R);
    vec2 C2 = intersect(a0.xy + n0 * R, v0, a2.xy + n1 * R, v1, a1.xy + n1 * R);
    vec2 C3 = intersect(a1.xy - n1 * R, v1, a3.xy - n2 * R, v2, a2.xy - n1 * R);
    vec2 C4 = intersect(a1.xy + n1 * R, v1, a3.xy + n2 * R, v2, a2.xy + n1 * R);
    f_side = vec3(n1, 0.0);
    f_way = way;
    f_rgb = v_rgb[1];
    // step 6: projection of the plane's corners (the paper writes ModelViewMatrix; the points
    // are already in view space, so it is the projection matrix)
    corner(C1, a1.z, -1.0);
    corner(C2, a1.z, 1.0);
    corner(C3, a2.z, -1.0);
    corner(C4, a2.z, 1.0);
    EndPrimitive();
}
