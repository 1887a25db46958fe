#version 430 core
// Approach 2 (paper, Table 2): one 8-byte record per cell with a visible face.
in uvec2 record;
flat out uvec2 v_record;
void main() { v_record = record; }
