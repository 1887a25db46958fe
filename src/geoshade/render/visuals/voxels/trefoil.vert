#version 430 core
// One control point per patch-quad. The patch index is carried explicitly
// (gl_InstanceID * PATCHES_PER_INSTANCE + gl_VertexID) instead of gl_PrimitiveID: llvmpipe
// re-uses patches once a draw tessellates more than 65,536 vertices (PLATFORM.md).
#pragma geoshade define PATCHES_PER_INSTANCE
flat out int v_patch;

void main() {
    v_patch = gl_InstanceID * PATCHES_PER_INSTANCE + gl_VertexID;
    gl_Position = vec4(0.0);
}
