#version 430 core
// Ray-casting proxy: the 12 triangles of the box [0, box_size] in voxel index space, made from
// gl_VertexID (no vertex buffer). Drawn with front faces culled, so one fragment per pixel comes
// from the box's back faces; this also works with the eye inside the box.
uniform ivec3 box_size;
uniform ivec3 brick_offset;  // where this box starts in the index space of mv (bricks; else 0)
uniform mat4 mv;
uniform mat4 proj;
out vec3 v_ocs;            // the proxy point in index space
const float PROXY_PAD = 1.0;

// corner v = (v & 1, v >> 1 & 1, v >> 2 & 1); two CCW triangles (seen from outside) per face
// +x, +y, +z, -x, -y, -z, the same quads as the cubes method
const int CORNERS[36] = int[36](
    1, 3, 7, 1, 7, 5,   2, 6, 7, 2, 7, 3,   4, 5, 7, 4, 7, 6,
    0, 4, 6, 0, 6, 2,   0, 1, 5, 0, 5, 4,   0, 2, 3, 0, 3, 1);

void main() {
    int v = CORNERS[gl_VertexID];
    // one voxel wider on every side: a pixel whose centre lies within the rasteriser's subpixel
    // snapping of the box's outline still gets its ray (the ray is clipped to the exact box in
    // the fragment shader; the extra fragments find nothing and are discarded)
    v_ocs = vec3(brick_offset) - PROXY_PAD
            + vec3(v & 1, (v >> 1) & 1, (v >> 2) & 1) * (vec3(box_size) + 2.0 * PROXY_PAD);
    gl_Position = proj * (mv * vec4(v_ocs, 1.0));
}
