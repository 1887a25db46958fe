#version 430 core
// Approach 3, faces storage: one record per visible face (cell << 3 | face, the depths of its
// corners A B C D) and its colour byte in a buffer of its own.
#include "cpgrid.glsl"
in uint face_head;
#if ZCORN_BITS == 16
in uvec4 face_z;
#else
in vec4 face_z;
#endif
in uint face_color;
flat out uint v_head;
flat out vec4 v_z;
flat out uint v_color;

void main() {
    v_head = face_head;
#if ZCORN_BITS == 16
    v_z = zdecode.x + vec4(face_z) * zdecode.y;
#else
    v_z = face_z;
#endif
    v_color = face_color;
}
