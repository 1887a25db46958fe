// Phong illumination with one directional light, in view space (VCS).
// Uniforms are set from geoshade.styles.light (Light, Material).
uniform vec3 light_dir;      // towards the light, view space, normalised
uniform vec4 material;       // ambient, diffuse, specular, shininess

vec3 phong(vec3 base, vec3 n_vcs, vec3 p_vcs) {
    vec3 n = normalize(n_vcs);
    vec3 v = normalize(-p_vcs);
    vec3 l = normalize(light_dir);
    float diff = max(dot(n, l), 0.0);
    vec3 r = reflect(-l, n);
    float spec = diff > 0.0 ? pow(max(dot(r, v), 0.0), material.w) : 0.0;
    return clamp(base * (material.x + material.y * diff) + vec3(material.z * spec), 0.0, 1.0);
}
