"""Lighting without GL: a directional light in view space and a Phong material."""

from __future__ import annotations

import math
from dataclasses import dataclass

from geoshade.errors import InputError


def _vec3(v, name: str) -> tuple[float, float, float]:
    try:
        t = tuple(float(a) for a in v)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected 3 numbers, got {v!r}") from None
    if len(t) != 3 or not all(math.isfinite(a) for a in t):
        raise InputError(f"{name}: expected 3 finite numbers, got {v!r}")
    return t


@dataclass(frozen=True)
class Light:
    """A directional light.

    direction: (3,) float  towards the light, in view space (x right, y up, z to the viewer),
                           normalised on construction
    color:     (3,) float  RGB intensity, 0..1

    Examples
    --------
    >>> [round(v, 4) for v in Light().direction]
    [0.3244, 0.4867, 0.8111]
    >>> Light((0, 0, 2)).to_uniforms()["light_dir"]
    (0.0, 0.0, 1.0)
    """

    direction: tuple[float, float, float] = (0.4, 0.6, 1.0)
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        d = _vec3(self.direction, "light direction")
        norm = math.sqrt(sum(a * a for a in d))
        if norm == 0.0:
            raise InputError("light direction: expected a non-zero vector, got (0, 0, 0)")
        object.__setattr__(self, "direction", tuple(a / norm for a in d))
        object.__setattr__(self, "color", _vec3(self.color, "light color"))

    def to_uniforms(self) -> dict[str, tuple[float, float, float]]:
        """``{"light_dir": (x, y, z), "light_color": (r, g, b)}``."""
        return {"light_dir": self.direction, "light_color": self.color}


@dataclass(frozen=True)
class Material:
    """Phong material coefficients.

    Examples
    --------
    >>> Material().to_uniforms()
    {'ambient': 0.25, 'diffuse': 0.75, 'specular': 0.2, 'shininess': 32.0}
    """

    ambient: float = 0.25
    diffuse: float = 0.75
    specular: float = 0.2
    shininess: float = 32.0

    def __post_init__(self) -> None:
        for name in ("ambient", "diffuse", "specular", "shininess"):
            v = getattr(self, name)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise InputError(f"material {name}: expected a number, got {v!r}") from None
            if not math.isfinite(f) or f < 0:
                raise InputError(f"material {name}: expected a number >= 0, got {v!r}")
            object.__setattr__(self, name, f)

    def to_uniforms(self) -> dict[str, float]:
        """``{"ambient", "diffuse", "specular", "shininess"}`` as floats."""
        return {
            "ambient": self.ambient,
            "diffuse": self.diffuse,
            "specular": self.specular,
            "shininess": self.shininess,
        }


@dataclass(frozen=True)
class Occlusion:
    """Ambient occlusion and a depth cue, applied over a finished picture from its depth
    buffer (``render/visuals/ambient``): creases, pores and the insides of steps darken, far
    surfaces dim, so a picture in one solid colour shows its 3D structure.

    strength:  how dark a fully enclosed crease gets, 0..1 (0: no occlusion)
    radius:    the size of the creases that darken, in model units (None: the part's default,
               e.g. 3 voxels for a core)
    depth_cue: how much the farthest surface of the model dims against the nearest, 0..1

    Depth-only: the depth of a pixel is compared with the chord between two opposite samples
    around it (the raw depth buffer is affine on a plane, so flat faces are untouched and only
    concave places darken), 8 directions at two distances.

    Examples
    --------
    >>> Occlusion().strength, Occlusion(strength="0.5").strength
    (0.7, 0.5)
    >>> Occlusion(depth_cue=2)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: occlusion depth_cue: expected a number in 0..1, got 2
    """

    strength: float = 0.7
    radius: float | None = None
    depth_cue: float = 0.3

    def __post_init__(self) -> None:
        for name in ("strength", "depth_cue"):
            v = getattr(self, name)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise InputError(f"occlusion {name}: expected a number in 0..1, got {v!r}"
                                 ) from None
            if not (0.0 <= f <= 1.0):
                raise InputError(f"occlusion {name}: expected a number in 0..1, got {v!r}")
            object.__setattr__(self, name, f)
        if self.radius is not None:
            try:
                r = float(self.radius)
            except (TypeError, ValueError):
                r = math.nan
            if not (math.isfinite(r) and r > 0):
                raise InputError(f"occlusion radius: expected a positive length, got "
                                 f"{self.radius!r}")
            object.__setattr__(self, "radius", r)

    @classmethod
    def parse(cls, value) -> Occlusion | None:
        """None/False -> None (off); True -> the default; an Occlusion as is; a dict of its
        fields."""
        if value is None or value is False:
            return None
        if value is True:
            return cls()
        if isinstance(value, cls):
            return value
        if isinstance(value, dict):
            unknown = set(value) - {"strength", "radius", "depth_cue"}
            if unknown:
                raise InputError(f"occlusion: unknown field(s) {sorted(unknown)}; expected "
                                 "strength, radius, depth_cue")
            return cls(**value)
        raise InputError(f"occlusion: expected true/false or a dict of strength, radius, "
                         f"depth_cue, got {value!r}")
