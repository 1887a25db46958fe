#version 430 core
// Re-render of the captured surface (mesh cache): the triangles the geometry shader emitted for
// the current step, level and colouring, read back from the transform-feedback buffer, with the
// geometry shader's own outputs and gl_Position; iso.frag shades them as it shades the live ones.
in vec3 in_pos;
in vec3 in_normal;
in float in_value;
out vec3 m_pos;
out vec3 m_normal;
out float m_value;
uniform mat4 mvp;

void main() {
    m_pos = in_pos;
    m_normal = in_normal;
    m_value = in_value;
    gl_Position = mvp * vec4(m_pos, 1.0);
}
