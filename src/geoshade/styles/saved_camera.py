"""A camera as it was used for a picture, as JSON: what ``--save-camera`` writes and
``--camera`` reads (:class:`SavedCamera`; :meth:`geoshade.render.camera.Camera.saved` and
:meth:`~geoshade.render.camera.Camera.from_saved` convert)."""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from geoshade.errors import InputError


def _number(value, what: str, positive: bool = False, allow_none: bool = False):
    """A finite (or positive) number, else one line; None passes with ``allow_none``
    (:mod:`geoshade.styles.options` checks its numbers with this too)."""
    if value is None and allow_none:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected a number, got {value!r}") from None
    if not math.isfinite(v) or (positive and v <= 0):
        raise InputError(f"{what}: expected a {'positive' if positive else 'finite'} number, "
                         f"got {value!r}")
    return v


def _flag(value, what: str) -> bool:
    if isinstance(value, bool):
        return value
    raise InputError(f"{what}: expected true or false, got {value!r}")


#: the marker and version of a saved camera's JSON
CAMERA_JSON = "geoshade_camera"
#: the format versions this geoshade reads
CAMERA_VERSIONS = (1,)
#: how far (in model radii) a saved camera may be from its model, and the largest radius
#: (GL draws in float32: beyond these a matrix is singular or the picture garbage)
MAX_RADII, MAX_RADIUS = 1e6, 1e30


def _vector(value, n: int, what: str) -> tuple[float, ...]:
    try:
        v = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected {n} numbers, got {value!r}") from None
    if len(v) != n or not all(math.isfinite(x) for x in v):
        raise InputError(f"{what}: expected {n} finite numbers, got {value!r}")
    return v


@dataclass(frozen=True)
class SavedCamera:
    """A camera as it was used for a picture (after framing): reading it back draws the same
    picture, pixel for pixel, from the same model at the same size.

    The fields of :class:`geoshade.render.camera.Camera`: ``target`` (3,), ``distance``,
    ``azimuth``, ``elevation`` (degrees), ``fovy`` (degrees), ``ortho``, ``half_height``,
    ``aspect``, ``radius``, ``box`` (the framed box, or None) and ``viewport`` (the NDC
    rectangle the view fills, or None). As JSON (:meth:`to_json`) every float is written with
    the digits that read back to the same double.

    Examples
    --------
    >>> cam = SavedCamera((0, 0, 0), 10.0, 45.0, 30.0, 30.0, False, 1.0, 1.5, 2.0, None, None)
    >>> SavedCamera.from_json(cam.to_json()) == cam
    True
    >>> bad = {**cam.as_dict(), "target": [0, 0]}
    >>> SavedCamera.from_dict(bad, "cam.json")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: cam.json: camera target: expected 3 finite numbers, got [0, 0]
    """

    target: tuple[float, float, float]
    distance: float
    azimuth: float
    elevation: float
    fovy: float
    ortho: bool
    half_height: float
    aspect: float
    radius: float
    box: tuple | None = None
    viewport: tuple | None = None

    @classmethod
    def from_dict(cls, d: dict, where: str = "") -> SavedCamera:
        """Check a camera's dict (as :meth:`as_dict` writes it); one line naming the field."""
        w = f"{where}: " if where else ""
        if not isinstance(d, dict) or CAMERA_JSON not in d:
            raise InputError(f"{w}not a geoshade camera (expected a JSON object with "
                             f"\"{CAMERA_JSON}\": 1, as --save-camera writes it)")
        version = d[CAMERA_JSON]
        if isinstance(version, bool) or version not in CAMERA_VERSIONS:
            raise InputError(f"{w}{CAMERA_JSON}: format version {version!r} is not one this "
                             f"geoshade reads ({', '.join(map(str, CAMERA_VERSIONS))}); save the "
                             "camera again with this version")
        missing = [f.name for f in dataclasses.fields(cls)
                   if f.name not in d and f.name not in ("box", "viewport")]
        if missing:
            raise InputError(f"{w}camera: {', '.join(missing)} missing")

        def num(key, positive=False):
            return _number(d[key], f"{w}camera {key}", positive)

        box = d.get("box")
        if box is not None:
            try:
                lo, hi = box
            except (TypeError, ValueError):
                raise InputError(f"{w}camera box: expected two corners [[x, y, z], [x, y, z]], "
                                 f"got {box!r}") from None
            box = (_vector(lo, 3, f"{w}camera box"), _vector(hi, 3, f"{w}camera box"))
        vp = d.get("viewport")
        if vp is not None:
            vp = _vector(vp, 4, f"{w}camera viewport")
        el = num("elevation")
        if not -90.0 <= el <= 90.0:
            raise InputError(f"{w}camera elevation: expected -90..90 degrees, got {el:g}")
        cam = cls(_vector(d["target"], 3, f"{w}camera target"),  # type: ignore[arg-type]
                  num("distance", True), num("azimuth"), el, num("fovy", True),
                  _flag(d["ortho"], f"{w}camera ortho"), num("half_height", True),
                  num("aspect", True), num("radius", True), box, vp)
        cam._check_bounds(w)
        return cam

    def _check_bounds(self, w: str) -> None:
        """Values a picture can be drawn with: 0 < fovy < 180 (at most 179), an aspect within
        1e-6..1e6, distance, half height and target within :data:`MAX_RADII` radii of the
        model (its box's centre when the camera has one)."""
        if not 0 < self.fovy <= 179:
            raise InputError(f"{w}camera fovy: expected 0 < fovy < 180 degrees (at most 179), "
                             f"got {self.fovy:g}")
        if not 1e-6 <= self.aspect <= 1e6:
            raise InputError(f"{w}camera aspect: expected 1e-6..1e6, got {self.aspect:g}")
        r = self.radius
        if r > MAX_RADIUS:
            raise InputError(f"{w}camera radius: expected at most {MAX_RADIUS:g}, got {r:g}")
        for key in ("distance", "half_height"):
            v = getattr(self, key)
            if v > MAX_RADII * r:
                raise InputError(f"{w}camera {key}: {v:g} is more than {MAX_RADII:g} times the "
                                 f"model's radius {r:g}; expected a camera near its model")
        if self.box is not None:
            centre = [(a + b) / 2 for a, b in zip(*self.box, strict=True)]
            size = max(abs(b - a) for a, b in zip(*self.box, strict=True))
            if size > 2 * MAX_RADIUS:
                raise InputError(f"{w}camera box: expected a size of at most {2 * MAX_RADIUS:g}, "
                                 f"got {size:g}")
            far = math.dist(centre, self.target)
            if far > MAX_RADII * r:
                raise InputError(f"{w}camera target: {far:g} from the model's centre, more "
                                 f"than {MAX_RADII:g} times its radius {r:g}")

    def as_dict(self) -> dict:
        """JSON-friendly: ``{"geoshade_camera": 1, "target": [...], ...}``."""
        d: dict[str, Any] = {CAMERA_JSON: 1}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if f.name == "box" and v is not None:
                v = [list(v[0]), list(v[1])]
            elif isinstance(v, tuple):
                v = list(v)
            d[f.name] = v
        return d

    def to_json(self) -> str:
        """The camera as JSON text."""

        return json.dumps(self.as_dict(), indent=2) + "\n"

    @classmethod
    def from_json(cls, text: str, where: str = "") -> SavedCamera:
        """A camera from JSON text (one line naming ``where`` when it is not one)."""

        try:
            d = json.loads(text)
        except ValueError as exc:
            raise InputError(f"{where + ': ' if where else ''}not valid JSON ({exc})") from None
        except RecursionError:  # 100,000 nested [ (a camera nests 2 deep)
            raise InputError(f"{where + ': ' if where else ''}not a geoshade camera: JSON nested "
                             "too deeply") from None
        return cls.from_dict(d, where)

    @classmethod
    def read(cls, path) -> SavedCamera:
        """A camera from a JSON file written by ``--save-camera`` (or :meth:`to_json`)."""

        p = Path(path)
        if not p.is_file():
            raise InputError(f"{path}: no such camera file (--camera)" if not p.exists() else
                             f"{path}: not a regular file; expected a camera JSON (--camera)")
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"{path}: cannot be read ({exc})") from None
        return cls.from_json(text, str(path))


__all__ = ["CAMERA_JSON", "SavedCamera"]
