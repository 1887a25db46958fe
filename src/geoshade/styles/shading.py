"""The uniforms of ``render/shaders/include/phong.glsl``, from a Light and a Material."""

from __future__ import annotations

from geoshade.styles.light import Light, Material


def shading_uniforms(light: Light | None = None, material: Material | None = None) -> dict:
    """``{"light_dir": (x, y, z), "material": (ambient, diffuse, specular, shininess)}``.

    >>> shading_uniforms()["material"]
    (0.25, 0.75, 0.2, 32.0)
    """
    light = light or Light()
    m = material or Material()
    return {"light_dir": light.direction,
            "material": (m.ambient, m.diffuse, m.specular, m.shininess)}
