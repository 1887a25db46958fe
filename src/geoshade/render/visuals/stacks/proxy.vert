#version 430 core
// Ray-casting proxy: the 12 triangles of the box [box_lo, box_hi] in index space (x, y in
// columns, z in levels), made from gl_VertexID. Drawn with front faces culled, so each pixel gets
// one fragment from the box's back faces; this also works with the eye inside the box.
uniform vec3 box_lo;
uniform vec3 box_hi;
uniform mat4 mv;
uniform mat4 proj;
out vec3 v_ocs;            // the proxy point in index space

// corner v = (v & 1, v >> 1 & 1, v >> 2 & 1); two CCW triangles (seen from outside) per face
const int CORNERS[36] = int[36](
    1, 3, 7, 1, 7, 5,   2, 6, 7, 2, 7, 3,   4, 5, 7, 4, 7, 6,
    0, 4, 6, 0, 6, 2,   0, 1, 5, 0, 5, 4,   0, 2, 3, 0, 3, 1);

void main() {
    int v = CORNERS[gl_VertexID];
    vec3 f = vec3(v & 1, (v >> 1) & 1, (v >> 2) & 1);
    v_ocs = mix(box_lo, box_hi, f);
    gl_Position = proj * (mv * vec4(v_ocs, 1.0));
}
