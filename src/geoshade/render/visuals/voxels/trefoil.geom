#version 430 core
// Algorithm of construction of visible "trefoil" (paper, Section 4), shared by the trefoil and
// gs methods. Emits the strip S_t (10 vertices, 8 triangles of which 2 degenerate) with the face
// normal written for the provoking (last) vertex of each triangle.
#pragma geoshade define TREFOIL_S
#pragma geoshade define TREFOIL_N
layout(points) in;
layout(triangle_strip, max_vertices = 10) out;

#include "voxel_common.glsl"

flat in ivec3 vox[];
out vec3 f_pos;            // view space
flat out vec3 f_normal;    // view space
flat out vec4 f_color;

uniform mat4 mv;
uniform mat4 proj;
uniform mat3 normal_matrix;
uniform vec3 eye_ocs;        // eye in the box's voxel index space
uniform int trefoil_mode;    // 0: per voxel from the eye, 1: paper Eq. (1) for the frame
uniform ivec3 frame_b;       // b_0, b_1, b_2 of Eq. (1) (mode 1)
uniform int cull_hidden;     // 1: skip voxels whose three camera-facing neighbours are selected

const int S[80] = TREFOIL_S;
const int N[80] = TREFOIL_N;

void main() {
    ivec3 p = vox[0];
    if (!selected(p)) return;                              // step 2
    ivec3 b = trefoil_mode == 0
        ? ivec3(greaterThanEqual(eye_ocs, vec3(p) + 0.5))
        : frame_b;
    if (cull_hidden != 0) {
        ivec3 d = 2 * b - 1;
        if (selected(p + ivec3(d.x, 0, 0)) && selected(p + ivec3(0, d.y, 0))
            && selected(p + ivec3(0, 0, d.z))) return;
    }
    int t = b.x + 2 * b.y + 4 * b.z;                       // Eq. (1)
    vec4 color = voxel_color(p);                           // step 7
    for (int s = 0; s < 10; ++s) {                         // steps 6 and 8
        int v = S[t * 10 + s];
        vec3 corner = vec3(p) + vec3(v & 1, (v >> 1) & 1, (v >> 2) & 1);
        vec4 pv = mv * vec4(corner, 1.0);
        f_pos = pv.xyz;
        f_normal = normal_matrix * face_normal_ocs(N[t * 10 + s]);
        f_color = color;
        gl_Position = proj * pv;
        EmitVertex();
    }
    EndPrimitive();
}
