// The x-ray pass of the wells: the parts of a well hidden behind the grid are drawn on top of
// it as a half-tone (one pixel in four left out, a lighter colour), so a well inside an opaque
// grid stays visible, keeps its colour and reads as "behind"; the visible parts are solid.
bool xray_hole(int xray) {
    ivec2 p = ivec2(gl_FragCoord.xy);
    return xray != 0 && ((p.x & 1) == 1) && ((p.y & 1) == 1);
}

vec3 xray_color(vec3 rgb, int xray) {
    return xray != 0 ? mix(rgb, vec3(1.0), 0.25) : rgb;
}
