#version 430 core
// Approach 3 (paper): the element buffer holds ZCORN indices, four per visible face (corners
// A B C D, drawn as lines_adjacency); the vertex shader finds the cell and its corner from the
// index (gl_VertexID) and the position from COORD and ZCORN.
#include "cpgrid.glsl"
uniform mat4 mv;
out vec3 v_pos;
flat out uint v_cell;

void main() {
    uint idx = uint(gl_VertexID);
    uint x = idx % uint(2 * dims.x);
    uint rest = idx / uint(2 * dims.x);
    uint y = rest % uint(2 * dims.y);
    uint z = rest / uint(2 * dims.y);
    ivec3 cell = ivec3(int(x / 2u), int(y / 2u), int(z / 2u));
    int corner = int(x & 1u) + 2 * int(y & 1u) + 4 * int(z & 1u);
    v_pos = (mv * vec4(corner_at(cell, corner, zcorn_at(idx)), 1.0)).xyz;
    v_cell = uint(cell.x) + uint(dims.x) * (uint(cell.y) + uint(dims.y) * uint(cell.z));
}
