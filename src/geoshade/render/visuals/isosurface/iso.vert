#version 430 core
// One control point per patch-quad. The running number g of the patch is carried explicitly
// (gl_InstanceID * patches_per_instance + gl_VertexID) instead of gl_PrimitiveID: llvmpipe
// re-uses patches once one draw tessellates more than 65,536 vertices (PLATFORM.md).
// patch_first: the first patch of this draw (a march in slabs of slices draws each slab's
// patches apart).
uniform int patches_per_instance;
uniform int patch_first;
flat out int v_patch;

void main() {
    v_patch = patch_first + gl_InstanceID * patches_per_instance + gl_VertexID;
    gl_Position = vec4(0.0);
}
