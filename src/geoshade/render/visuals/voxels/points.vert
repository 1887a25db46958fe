#version 430 core
// The paper's GS method: one stored point per selected voxel (linear index in the box).
in uint voxel_linear;
uniform ivec3 box_size;
flat out ivec3 vox;

void main() {
    uint n = uint(box_size.x), m = uint(box_size.y);
    vox = ivec3(int(voxel_linear % n), int((voxel_linear / n) % m), int(voxel_linear / (n * m)));
    gl_Position = vec4(0.0);
}
