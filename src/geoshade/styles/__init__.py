"""Appearance without GL: colour palettes, light and material."""

from geoshade.styles.light import Light, Material
from geoshade.styles.palette import palette, random_palette

__all__ = ["Light", "Material", "palette", "random_palette"]
