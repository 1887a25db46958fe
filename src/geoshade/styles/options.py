"""Typed view options, parsed once and checked before any GL context exists.

Every part's View takes its options as one frozen dataclass (a subclass of :class:`ViewOptions`);
the values shared by all parts are value objects defined here:

- :class:`CameraSpec` -- named view, azimuth, elevation, zoom, orthographic;
- :class:`Plane` -- one cutting plane with one meaning in every part: model coordinates
  (x east, y north, z up, in the model's length unit, before vertical exaggeration); the side the
  normal points to is kept: ``NX,NY,NZ,D`` keeps the points with ``NX·x + NY·y + NZ·z >= D``;
  ``NX,NY,NZ`` alone is the plane through the centre of the model's bounds;
- :class:`ColorStyle` -- colour map, colour range, log scale, reversed, or one solid colour.

:meth:`ViewOptions.parse` turns keyword arguments into options: it resolves deprecated names
(with a :class:`~geoshade.errors.GeoshadeDeprecationWarning`), collects the camera shorthands
(``view azimuth elevation zoom ortho``) into a :class:`CameraSpec`, refuses unknown names with
the list of accepted ones and runs each field's ``check_<name>(value, model)``.

>>> CameraSpec.parse("top", zoom=2).zoom
2.0
>>> Plane.parse("1,0,0,500").keeps([[400, 0, 0], [600, 0, 0]]).tolist()
[False, True]
>>> ColorStyle.parse("magma", range=(0, 1)).range
(0.0, 1.0)
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import PurePath
from typing import Any, ClassVar, Self

import numpy as np

from geoshade.errors import GeoshadeDeprecationWarning, InputError
from geoshade.styles.checks import (
    bind_checks,
    check_bool,
    check_choice,
    check_exaggeration,
    check_number,
    check_range,
    checks,
)
from geoshade.styles.declare import Opt, derive_tables, option
from geoshade.styles.image import parse_size
from geoshade.styles.palette import colormap, palette
from geoshade.styles.saved_camera import CAMERA_JSON, SavedCamera, _number

#: view name -> (azimuth, elevation) in degrees; azimuth 0 looks from -y towards +y
VIEWS = {
    "iso": (45.0, math.degrees(math.atan(1 / math.sqrt(2)))),
    "top": (0.0, 90.0),
    "bottom": (0.0, -90.0),
    "front": (0.0, 0.0),
    "back": (180.0, 0.0),
    "left": (-90.0, 0.0),
    "right": (90.0, 0.0),
}
#: the options a :class:`ViewOptions` collects into its ``camera`` (:class:`CameraSpec`):
#: name -> its declaration (:class:`~geoshade.styles.declare.Opt`)
CAMERA_OPTIONS: dict[str, Opt] = {
    "view": Opt(help="named view", group="camera", choices=tuple(VIEWS), example="top"),
    "azimuth": Opt(help="degrees, overrides the view's (0 looks from the south, 90 from the "
                        "east)", group="camera", type=float, metavar="DEG", example=120.0,
                   control=""),   # the mouse turns the camera in the viewers
    "elevation": Opt(help="degrees -90..90, overrides the view's", group="camera", type=float,
                     metavar="DEG", example=60.0, control=""),
    "zoom": Opt(help="zoom factor (1 frames the whole model)", group="camera", type=float,
                metavar="F", example=1.6, control=""),
    "ortho": Opt(help="orthographic projection", group="camera", form="switch", example=True),
}
CAMERA_KEYS = tuple(CAMERA_OPTIONS)
#: whether pictures carry their annotations when ``annotations`` is not given (the test suite
#: turns it off for its exact-oracle comparisons, see tests/conftest.py)
ANNOTATIONS_DEFAULT = True
#: the options collected into a ``color`` option (:class:`ColorStyle`): name -> (its field of
#: the style, its declaration)
COLOR_OPTIONS: dict[str, tuple[str, Opt]] = {
    "colormap": ("colormap", Opt(
        help="colour map: matplotlib's names (viridis, the default; NAME_r reversed) and, "
             "with the colors extra, colorcet's (fire, rainbow4...)", group="colour",
        metavar="NAME", control="colormap", example="magma")),
    "color_range": ("range", Opt(
        help="values spread over the colour map (default: the part's: the property's range, "
             "the selection...)", group="colour", nargs=2, type=float,
        metavar=("LO", "HI"), example=lambda model=None: (0.1, 0.3))),
    "log": ("log", Opt(
        help="logarithmic colour scale (default: automatic for permeability-like properties "
             "spanning more than three decades)", group="colour", form="switch",
        off_flag="--linear", example=True)),
    "reverse": ("reverse", Opt(help="reverse the colour map", group="colour", form="switch",
                               example=True)),
    "solid_color": ("solid", Opt(
        help="one colour for everything shown (a name, #rrggbb or R,G,B 0..1)", group="colour",
        metavar="COLOR", control="", example="tan")),
    "palette": ("palette", Opt(help="an explicit (256, 4) uint8 palette (Python only)",
                               group="colour", flag=None, control="")),
    "nan_color": ("nan_color", Opt(
        help="colour of what has no value (NaN; not positive on a log scale; light grey)",
        group="colour", metavar="COLOR", control="", example="red")),
    "categorical": ("categorical", Opt(
        help="integer codes drawn as categories, one colour and one legend entry each "
             "(default: automatic for integer codes and region/facies keywords such as "
             "FACIES, ZONE, SATNUM, FIPNUM); --continuous: a colour map and a colour bar",
        group="colour", form="switch", off_flag="--continuous", example=False)),
}
#: keyword arguments collected into a ``color`` option: name -> field of :class:`ColorStyle`
COLOR_KEYS = {name: fld for name, (fld, _) in COLOR_OPTIONS.items()}
#: the colour of cells without a value (NaN, or not positive on a log scale)
NAN_COLOR = (0.75, 0.75, 0.75, 1.0)
#: shorthand option names (camera, colour) that a ``CHOICES`` table may name besides fields
SHORTHANDS = (*CAMERA_KEYS, *COLOR_KEYS)
#: shorthand name -> the option field it changes (``camera`` or ``color``)
SHORTHAND_FIELD = {**dict.fromkeys(CAMERA_KEYS, "camera"), **dict.fromkeys(COLOR_KEYS, "color")}


def _fields_of(value, cls, key: str, what: str, name: str) -> dict[str, Any]:
    """The fields of a value object given as None, an instance, a string (``key``) or a dict."""
    if value is None:
        return {}
    if isinstance(value, cls):
        return {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
    if isinstance(value, str):
        return {key: value}
    if isinstance(value, dict):
        return dict(value)
    raise InputError(f"{what}: expected {name}, a {cls.__name__} or a dict, got "
                     f"{type(value).__name__}")


# ==============================================================================================
# camera
# ==============================================================================================
def _is_camera_file(value) -> bool:

    return isinstance(value, PurePath) or (isinstance(value, str)
                                           and value.strip().lower().endswith(".json"))


@dataclass(frozen=True)
class CameraSpec:
    """Where the camera looks from; framing on the model's bounds is done by the View.

    view:      a named view (``iso top bottom front back left right``)
    azimuth:   degrees, overrides the view's (0 looks from -y towards +y, 90 from +x)
    elevation: degrees -90..90, overrides the view's
    zoom:      > 0; 1 frames the whole model
    ortho:     orthographic projection
    saved:     a :class:`SavedCamera` used as it is instead of framing (from a camera JSON
               file written by ``--save-camera``: the same picture again)
    """

    view: str = "iso"
    azimuth: float | None = None
    elevation: float | None = None
    zoom: float = 1.0
    ortho: bool = False
    saved: SavedCamera | None = None

    @classmethod
    def parse(cls, value=None, **changes) -> CameraSpec:
        """A camera spec from None, a spec, a view name, a dict, a saved camera or the path of
        a camera JSON file (``"cam.json"``), with ``changes`` applied.

        >>> CameraSpec.parse({"view": "front", "ortho": True}).ortho
        True
        >>> CameraSpec.parse("sideways")
        Traceback (most recent call last):
        ...
        geoshade.errors.InputError: view: unknown view 'sideways'; expected one of iso, top, \
bottom, front, back, left, right
        """
        saved = None
        early = {k: v for k, v in changes.items() if v is not None}
        if _is_camera_file(value) and early:   # before reading the file: the flags conflict
            raise InputError(f"camera: a saved camera fixes the view; give either it or "
                             f"{', '.join(sorted(early))}, not both")
        if isinstance(value, SavedCamera):
            saved, value = value, None
        elif _is_camera_file(value):
            saved, value = SavedCamera.read(value), None
        elif isinstance(value, dict) and CAMERA_JSON in value:
            saved, value = SavedCamera.from_dict(value), None
        given = {k: v for k, v in changes.items() if v is not None}
        if saved is not None and given:
            raise InputError(f"camera: a saved camera fixes the view; give either it or "
                             f"{', '.join(sorted(given))}, not both")
        base = _fields_of(value, cls, "view", "camera", "a view name")
        old = base.pop("saved", None)
        if saved is None and old is not None and not given:  # an existing spec, unchanged
            saved = old if isinstance(old, SavedCamera) else SavedCamera.from_dict(
                {CAMERA_JSON: 1, **old})
        base.update(given)
        unknown = set(base) - set(CAMERA_KEYS)
        if unknown:
            raise InputError(f"camera: unknown {', '.join(sorted(unknown))}; it takes "
                             f"{', '.join(CAMERA_KEYS)}")
        view = base.get("view") or "iso"
        if view not in VIEWS:
            raise InputError(f"view: unknown view {view!r}; expected one of {', '.join(VIEWS)}")
        az = _number(base.get("azimuth"), "azimuth", allow_none=True)
        el = _number(base.get("elevation"), "elevation", allow_none=True)
        if el is not None and not -90.0 <= el <= 90.0:
            raise InputError(f"elevation: expected -90..90 degrees, got {el:g}")
        zoom = _number(1.0 if base.get("zoom") is None else base["zoom"], "zoom", positive=True)
        ortho = check_bool(base.get("ortho") or False, "ortho")
        return cls(view, az, el, zoom, ortho, saved)

    def angles(self) -> tuple[float, float]:
        """(azimuth, elevation) in degrees: the view's, overridden where given."""
        az, el = VIEWS[self.view]
        return (az if self.azimuth is None else self.azimuth,
                el if self.elevation is None else self.elevation)


# ==============================================================================================
# plane
# ==============================================================================================
@dataclass(frozen=True)
class Plane:
    """A cutting plane: keeps the points ``p`` with ``n̂·p >= offset``.

    normal: (3,) float   unit normal (x east, y north, z up); the kept side is where it points
    offset: float|None   signed distance of the plane from the origin along ``normal``, in the
                         model's length unit; None: the plane goes through the model's centre
                         (resolved by the View with :meth:`resolve`)

    Examples
    --------
    >>> p = Plane.parse("0,0,2")           # through the centre, keep the upper half
    >>> p.normal, p.offset
    ((0.0, 0.0, 1.0), None)
    >>> p.resolve([10, 10, 50]).offset
    50.0
    >>> Plane.parse([1, 0, 0, -5]).signed([[0, 0, 0]]).tolist()
    [5.0]
    """

    normal: tuple[float, float, float] = (1.0, 0.0, 0.0)
    offset: float | None = None

    @classmethod
    def parse(cls, value) -> Plane | None:
        """None, a Plane, ``"NX,NY,NZ[,D]"`` or 3/4 numbers -> Plane (None stays None)."""
        if value is None or isinstance(value, Plane):
            return value
        expect = ("plane: expected NX,NY,NZ (through the model's centre) or NX,NY,NZ,D "
                  "(NX·x + NY·y + NZ·z >= D is kept; x east, y north, z up)")
        try:
            vals = ([float(v) for v in value.replace(";", ",").split(",")]
                    if isinstance(value, str) else [float(v) for v in value])
        except (TypeError, ValueError):
            raise InputError(f"{expect}, got {value!r}") from None
        if len(vals) not in (3, 4) or not all(math.isfinite(v) for v in vals):
            raise InputError(f"{expect}, got {value!r}")
        n = np.asarray(vals[:3])
        length = float(np.linalg.norm(n))
        if not length > 0:
            raise InputError(f"plane: the normal must not be zero, got {value!r}")
        unit = tuple(float(v) + 0.0 for v in n / length)
        return cls(unit, None if len(vals) == 3 else vals[3] / length)  # type: ignore[arg-type]

    @classmethod
    def across(cls, box, axis: str, fraction: float, flip: bool = False) -> Plane:
        """The plane across ``axis`` (``x``, ``y`` or ``z``) at ``fraction`` of the ``(2, 3)``
        ``box`` (clipped to 0.01..0.99) that keeps the near side (coordinates below it; the
        far side with ``flip``): a viewer's section control.

        >>> Plane.across([[0, 0, 0], [10, 20, 30]], "y", 0.25)
        Plane(normal=(0.0, -1.0, 0.0), offset=-5.0)
        """
        if axis not in ("x", "y", "z"):
            raise InputError(f"section: expected axis x, y or z, got {axis!r}")
        try:
            f = float(fraction)
        except (TypeError, ValueError):
            f = float("nan")
        if not math.isfinite(f):
            raise InputError(f"section: expected a fraction 0..1 of the box, got {fraction!r}")
        k = "xyz".index(axis)
        b = np.asarray(box, float)
        pos = b[0, k] + float(np.clip(f, 0.01, 0.99)) * (b[1, k] - b[0, k])
        n = np.zeros(3)
        n[k] = 1.0 if flip else -1.0
        return cls(tuple(float(v) + 0.0 for v in n), float(n[k] * pos) + 0.0)  # type: ignore

    @classmethod
    def through(cls, point, normal) -> Plane:
        """The plane through ``point`` with ``normal`` (kept side: where it points)."""
        p = cls.parse(list(normal))
        assert p is not None
        return p.resolve(point)

    def resolve(self, centre) -> Plane:
        """This plane with its offset set (through ``centre`` when it had none)."""
        if self.offset is not None:
            return self
        return Plane(self.normal, float(np.dot(self.normal, np.asarray(centre, float))))

    def signed(self, points) -> np.ndarray:
        """``n̂·p - offset`` of ``(n, 3)`` points: >= 0 on the kept side."""
        if self.offset is None:
            raise InputError("plane: resolve the plane (it goes through the model's centre) "
                             "before using it")
        p = np.asarray(points, float).reshape(-1, 3)
        return p @ np.asarray(self.normal) - self.offset

    def keeps(self, points) -> np.ndarray:
        """Bool mask of the points on the kept side (on the plane counts as kept)."""
        return self.signed(points) >= 0

    def crosses(self, bounds) -> bool:
        """True when the plane has corners of the ``(2, 3)`` box on both sides (or on it)."""
        b = np.asarray(bounds, float)
        corners = np.array([[b[i, 0], b[j, 1], b[k, 2]] for i in (0, 1) for j in (0, 1)
                            for k in (0, 1)])
        s = self.signed(corners)
        return bool(s.min() <= 0 <= s.max())

    def text(self) -> str:
        """``NX,NY,NZ,D`` as written on a command line."""
        vals = [*self.normal, *(() if self.offset is None else (self.offset,))]
        return ",".join(f"{v:g}" for v in vals)


# ==============================================================================================
# colour
# ==============================================================================================
def _rgba(value, what: str) -> tuple[float, float, float, float]:
    if isinstance(value, str) and value.count(",") in (2, 3):   # "R,G,B[,A]" as typed
        value = value.split(",")
    if isinstance(value, str):
        from matplotlib.colors import to_rgba

        try:
            return tuple(float(v) for v in to_rgba(value))  # type: ignore[return-value]
        except ValueError:
            raise InputError(f"{what}: unknown colour {value!r}; expected a name such as "
                             "'tan' or '#c8b48c'") from None
    try:
        vals = [float(v) for v in value]
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected a colour name or 3/4 numbers, got {value!r}") from None
    if len(vals) not in (3, 4) or not all(math.isfinite(v) for v in vals):
        raise InputError(f"{what}: expected 3 or 4 numbers (RGB[A]), got {value!r}")
    if max(vals) > 1.0:  # 0..255
        vals = [v / 255.0 for v in vals]
    if len(vals) == 3:
        vals.append(1.0)
    if min(vals) < 0 or max(vals) > 1:
        raise InputError(f"{what}: components must lie in 0..1 (or 0..255), got {value!r}")
    return tuple(vals)  # type: ignore[return-value]


@dataclass(frozen=True)
class ColorStyle:
    """How values become colours.

    colormap: a matplotlib colour map name (``viridis``, ``magma``, ``gray`` ...)
    range:    (lo, hi) of the values mapped onto the colour map; None: the part's default
    log:      map ``log10(value)`` (the range must be positive); None: the part decides
              (permeability-like properties spanning more than three decades: log, said on the
              colour bar and in the stats)
    reverse:  the colour map reversed
    solid:    one RGBA colour (0..1) for everything instead of the colour map (None: off)
    palette:  an explicit (256, 4) uint8 palette instead of the colour map (tests, pickers)
    nan_color: RGBA (0..1) of values without a colour (NaN; not positive on a log scale)
    categorical: integer codes drawn as categories (one qualitative colour and one legend
              entry per code): True, False (a colour bar), None: by the property's name and
              values (:func:`geoshade.styles.categories.is_categorical`)
    """

    #: the colour scales a user picks from: ``log`` None (auto), False (linear), True (log)
    SCALES: ClassVar[dict[str, bool | None]] = {"auto": None, "linear": False, "log": True}

    colormap: str = "viridis"
    range: tuple[float, float] | None = None
    log: bool | None = None
    reverse: bool = False
    solid: tuple[float, float, float, float] | None = None
    palette: Any = field(default=None, compare=False, repr=False)
    nan_color: tuple[float, float, float, float] = NAN_COLOR
    categorical: bool | None = None

    @classmethod
    def parse(cls, value=None, **changes) -> ColorStyle:
        """A style from None, a style, a colour map name or a dict, with ``changes`` applied.

        >>> ColorStyle.parse("gray_r").reverse, ColorStyle.parse("gray_r").colormap
        (True, 'gray')
        >>> ColorStyle.parse(log=True, range=(0, 10))
        Traceback (most recent call last):
        ...
        geoshade.errors.InputError: color range: a log colour scale needs LO > 0, got 0 10
        """
        base = _fields_of(value, cls, "colormap", "color", "a colour map name")
        base.update(changes)
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(base) - names
        if unknown:
            raise InputError(f"color: unknown {', '.join(sorted(unknown))}; it takes "
                             f"{', '.join(sorted(names))}")
        cmap = str(base.get("colormap") or "viridis")
        reverse = check_bool(base.get("reverse") or False, "reverse")
        if cmap.endswith("_r"):
            cmap, reverse = cmap[:-2], not reverse
        _check_colormap(cmap)
        rng = check_range(base.get("range"), "color range")
        log = None if base.get("log") is None else check_bool(base["log"], "log")
        if log and rng is not None and rng[0] <= 0:
            raise InputError(f"color range: a log colour scale needs LO > 0, got {rng[0]:g} "
                             f"{rng[1]:g}")
        solid = None if base.get("solid") is None else _rgba(base["solid"], "solid colour")
        pal = base.get("palette")
        if pal is not None:
            pal = np.asarray(pal, np.uint8)
            if pal.shape != (256, 4):
                raise InputError(f"palette: expected (256, 4) uint8 RGBA, got {pal.shape}")
        nan = NAN_COLOR if base.get("nan_color") is None else _rgba(base["nan_color"],
                                                                     "NaN colour")
        cat = base.get("categorical")
        cat = None if cat is None else check_bool(cat, "categorical")
        return cls(cmap, rng, log, reverse, solid, pal, nan, categorical=cat)

    def resolved(self, name: str, values) -> tuple[ColorStyle, bool]:
        """``(style, auto)``: this style with ``log`` decided -- as given, else log for a
        permeability-like ``name`` (PERM*, K*, TRANS*, MOBIL*) whose positive values span more
        than three decades (``auto`` True then).

        >>> import numpy as np
        >>> s, auto = ColorStyle().resolved("PERMX", np.array([0.003, 1, 10000]))
        >>> s.log, auto
        (True, True)
        >>> ColorStyle().resolved("PORO", np.array([0.01, 0.3]))[0].log
        False
        """
        if self.log is not None:
            return self, False
        n = str(name or "").upper()
        if n.startswith(("PERM", "TRAN", "MOBIL")) or (n[:1] == "K" and len(n) <= 3):
            v = np.asarray(values, np.float64)
            pos = v[np.isfinite(v) & (v > 0)]
            if pos.size and float(pos.max()) > 1e3 * float(pos.min()) and self.range is None:
                return dataclasses.replace(self, log=True), True
            if pos.size and self.range is not None and self.range[0] > 0 and \
                    self.range[1] > 1e3 * self.range[0]:
                return dataclasses.replace(self, log=True), True
        return dataclasses.replace(self, log=False), False

    def with_(self, **changes) -> ColorStyle:
        """A checked copy with ``changes``."""
        return ColorStyle.parse(self, **changes)

    def palette_rgba(self) -> np.ndarray:
        """(256, 4) uint8: the solid colour everywhere, the explicit palette, or the colour map
        (reversed if asked)."""
        if self.solid is not None:
            rgba = np.clip(np.rint(np.asarray(self.solid) * 255), 0, 255).astype(np.uint8)
            return np.ascontiguousarray(np.broadcast_to(rgba, (256, 4)))
        if self.palette is not None:
            return np.asarray(self.palette, np.uint8)

        return palette(self.colormap + ("_r" if self.reverse else ""))

    def nan_palette(self) -> np.ndarray:
        """(256, 4) uint8 for values with gaps: entries 0..254 the colour map (sampled at 255
        levels), entry 255 :attr:`nan_color` (see :meth:`nan_index`)."""
        pal = self.palette_rgba()
        levels = np.rint(np.linspace(0, 255, 255)).astype(int)
        out = np.empty((256, 4), np.uint8)
        out[:255] = pal[levels]
        out[255] = np.clip(np.rint(np.asarray(self.nan_color) * 255), 0, 255).astype(np.uint8)
        return out

    @staticmethod
    def nan_index(t, lo: float, hi: float) -> np.ndarray:
        """uint8 indices into :meth:`nan_palette` of transformed values ``t`` over ``lo..hi``:
        0..254 by value, 255 where there is none.

        >>> ColorStyle.nan_index(np.array([0.0, 1.0, np.nan]), 0.0, 1.0).tolist()
        [0, 254, 255]
        """
        v = np.asarray(t, np.float64)
        span = float(hi) - float(lo)
        with np.errstate(invalid="ignore"):
            u = (v - lo) / span if span > 0 else np.zeros_like(v)
        out = np.clip(np.rint(np.nan_to_num(u, nan=0.0, posinf=1.0, neginf=0.0) * 254), 0, 254)
        out[~np.isfinite(v)] = 255
        return out.astype(np.uint8)

    def transform(self, values) -> np.ndarray:
        """``log10(values)`` for a log style (non-positive values become NaN), else values."""
        v = np.asarray(values, np.float64)
        if not self.log:
            return v
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(v > 0, np.log10(np.where(v > 0, v, 1.0)), np.nan)

    def transformed_range(self, lo: float, hi: float) -> tuple[float, float]:
        """The range in transformed units (``log10`` of a positive range for a log style)."""
        if not self.log:
            return float(lo), float(hi)
        if lo <= 0:
            raise InputError(f"color range: a log colour scale needs LO > 0, got {lo:g} {hi:g}")
        return math.log10(lo), math.log10(hi)

    def default_range(self, values) -> tuple[float, float]:
        """The finite (log: positive) range of ``values``; (0, 1) when there is none.

        >>> ColorStyle(log=True).default_range([0, 1, 100, np.nan])
        (1.0, 100.0)
        """
        v = np.asarray(values, np.float64)
        ok = np.isfinite(v) & ((v > 0) if self.log else True)
        if not ok.any():
            return (1.0, 10.0) if self.log else (0.0, 1.0)
        return float(v[ok].min()), float(v[ok].max())


def _check_colormap(name: str) -> None:

    colormap(name)


def _defaults(cls) -> dict:
    out = {}
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            out[f.name] = f.default
        elif f.default_factory is not dataclasses.MISSING:
            out[f.name] = f.default_factory()
    return out


# ==============================================================================================
# the options of a View
# ==============================================================================================
#: a deprecated option: new name and a converter ``f(value, model) -> new value`` (or None)
Deprecated = tuple[str, Callable[[Any, Any], Any] | None]


@dataclass(frozen=True)
class ViewOptions:
    """What every View takes; each part's options extend it.

    size:        (width, height) of the picture in pixels
    camera:      :class:`CameraSpec` (shorthands ``view azimuth elevation zoom ortho`` work too)
    transparent: background alpha 0
    background:  RGB 0..1 behind the model
    annotations: title and time, colour bar or legend, axes triad and (map views) scale bar
                 over the picture (:mod:`geoshade.styles.annotate`); False: the bare render
    """

    size: tuple[int, int] = option(
        (1024, 768), help="picture size in pixels, WxH", group="picture", metavar="WxH",
        control="", example=(320, 200))
    camera: CameraSpec = option(
        factory=CameraSpec, flag="--camera", metavar="FILE.json", group="camera", control="",
        help="the camera saved by --save-camera (or the viewer's Save camera): the same view "
             "again, pixel for pixel at the same size; instead of --view/--azimuth/--elevation/"
             "--zoom/--ortho")
    transparent: bool = option(False, help="background alpha 0", form="switch",
                               group="picture", control="", example=True)
    background: tuple[float, float, float] = option(
        (1.0, 1.0, 1.0), help="colour behind the model (a name, #rrggbb or R,G,B 0..1)",
        group="picture", metavar="COLOR", control="", example=(0.9, 0.9, 1.0))
    annotations: bool = option(
        factory=lambda: ANNOTATIONS_DEFAULT, form="switch", group="picture", example=False,
        help="title and time, colour bar or legend, axes triad and (map views) scale bar over "
             "the picture; --no-annotations: the bare render")

    #: old option name -> (new name, converter or None); used with a deprecation warning
    DEPRECATED: ClassVar[dict[str, Deprecated]] = {}
    #: what the part is called in messages
    PART: ClassVar[str] = "view"
    #: shorthands of the colour style a part does not take (e.g. the core has no log scale)
    NO_COLOR: ClassVar[tuple[str, ...]] = ()
    #: named sets of options a flag sets at once (``--paper``: the paper's method)
    PRESETS: ClassVar[dict[str, tuple[str, dict]]] = {}
    #: derived from the declarations: field -> the words it takes (the CLI and the viewers take
    #: their choices from here)
    CHOICES: ClassVar[dict[str, tuple]] = {"view": tuple(VIEWS)}
    #: derived from the declarations: the true/false fields
    FLAGS: ClassVar[tuple[str, ...]] = ("transparent", "annotations")
    #: field -> its check ``f(value, model) -> value``, bound when the class is made
    #: (:func:`checks`, and the words and true/false fields of the declarations)
    _CHECKS: ClassVar[dict[str, Callable]] = {}
    #: field -> its declaration, made with the class
    _OPTS: ClassVar[dict[str, Opt]] = {}
    #: the fields with words whose default is None (None passes their check)
    _NULLABLE: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kw) -> None:
        super().__init_subclass__(**kw)
        derive_tables(cls, ViewOptions, VIEWS)
        cls._CHECKS = bind_checks(cls, shorthands=SHORTHANDS)

    @classmethod
    def declarations(cls) -> dict[str, tuple[Opt, Any]]:
        """Every option this View takes by name, fields and shorthands, with its declaration
        and default: what the CLI, the viewers' panels and the tests read.

        >>> d = ViewOptions.declarations()
        >>> d["view"][0].choices[:2], d["annotations"][0].cli_off("annotations")
        (('iso', 'top'), '--no-annotations')
        """
        out: dict[str, tuple[Opt, Any]] = {}
        for name, opt in cls._OPTS.items():
            if name in ("camera", "color"):
                continue
            out[name] = (opt, cls.default(name))
        out["camera"] = (cls._OPTS["camera"], None)
        for name, opt in CAMERA_OPTIONS.items():
            out[name] = (opt, getattr(CameraSpec(), name))
        if cls._has_color():
            style = ColorStyle()
            for name, (fld, opt) in COLOR_OPTIONS.items():
                if name not in cls.NO_COLOR:
                    out[name] = (opt, getattr(style, fld))
        return out

    @classmethod
    def live(cls, name: str) -> bool:
        """Whether option ``name`` (a field or a shorthand) can change on an open View."""
        decl = cls.declarations().get(name)
        return True if decl is None else decl[0].live

    @classmethod
    def default(cls, name: str):
        """The default of field ``name`` (what the CLI and the viewer show as the default).

        >>> ViewOptions.default("size")
        (1024, 768)
        """
        for f in dataclasses.fields(cls):
            if f.name == name:
                if f.default is not dataclasses.MISSING:
                    return f.default
                if f.default_factory is not dataclasses.MISSING:
                    return f.default_factory()
        raise KeyError(f"{cls.__name__} has no option {name!r}")

    @classmethod
    def choices(cls, name: str) -> tuple:
        """The words option ``name`` takes (:attr:`CHOICES`).

        >>> ViewOptions.choices("view")[:3]
        ('iso', 'top', 'bottom')
        """
        return cls.CHOICES[name]

    @classmethod
    def _has_color(cls) -> bool:
        return any(f.name == "color" for f in dataclasses.fields(cls))

    @classmethod
    def names(cls) -> list[str]:
        """The option names this View takes (camera and colour shorthands included)."""
        return ([f.name for f in dataclasses.fields(cls)] + list(CAMERA_KEYS)
                + (list(COLOR_KEYS) if cls._has_color() else []))

    @classmethod
    def parse(cls, model=None, base: ViewOptions | None = None, **kw) -> Self:
        """Options from keyword arguments (on top of ``base``), every value checked.

        Raises InputError naming the option and what was expected; nothing here needs GL.
        """
        kw = dict(kw)
        for old, (new, convert) in cls.DEPRECATED.items():
            if old in kw:
                value = kw.pop(old)
                if value is None:
                    continue
                if new in kw and kw[new] is not None:
                    raise InputError(f"{old}: give either {old} (deprecated) or {new}, not both")
                warnings.warn(f"{old} is deprecated: use {new}"
                              + (" (see its documentation for the meaning)" if convert else ""),
                              GeoshadeDeprecationWarning, stacklevel=3)
                kw[new] = convert(value, model) if convert is not None else value
        names = set(cls.names())
        unknown = sorted(set(kw) - names)
        if unknown:
            raise InputError(f"{', '.join(unknown)}: not an option of the {cls.PART} view; it "
                             f"takes {', '.join(sorted(cls.names()))}")
        values = ({f.name: getattr(base, f.name) for f in dataclasses.fields(cls)}
                  if base is not None else _defaults(cls))
        cam_kw = {k: kw.pop(k) for k in CAMERA_KEYS if k in kw}
        if "camera" in kw or cam_kw:
            values["camera"] = CameraSpec.parse(kw.pop("camera", values.get("camera")),
                                                **cam_kw)
        col_kw = {COLOR_KEYS[k]: kw.pop(k) for k in list(COLOR_KEYS) if k in kw
                  and cls._has_color()}
        if cls._has_color() and ("color" in kw or col_kw):
            values["color"] = ColorStyle.parse(kw.pop("color", values.get("color")), **col_kw)
        changed = set(kw)
        values.update(kw)
        checked = {}
        for f in dataclasses.fields(cls):
            v = values[f.name]
            if base is None or f.name in changed:
                v = cls._CHECKS[f.name](v, model)
            checked[f.name] = v
        opts = cls(**checked)
        opts.validate(model)
        return opts

    def replace(self, model=None, **changes) -> Self:
        """A checked copy with ``changes`` (only the changed values are checked again), resolved
        against ``model`` when one is given (:meth:`resolve`)."""
        new = type(self).parse(model, base=self, **changes)
        return new.resolve(model) if model is not None else new

    def resolve(self, model, progress=None) -> Self:
        """These options with what needs the model's data decided (a core's ``select="auto"``:
        Otsu's threshold; its ROI fitted or its mask read). :meth:`parse` stays pure and cheap;
        every path (CLI, viewer, notebook, Python) resolves here, once. Resolving resolved
        options does nothing. The base has nothing to resolve."""
        return self

    def validate(self, model) -> None:
        """Checks across fields (after every field was checked); subclasses extend it."""

    # --- checks of the shared fields -----------------------------------------------------------
    @staticmethod
    @checks("size")
    def check_size(value, model=None) -> tuple[int, int]:
        return parse_size(value)

    @staticmethod
    @checks("camera")
    def check_camera(value, model=None) -> CameraSpec:
        return CameraSpec.parse(value)

    @staticmethod
    @checks("background")
    def check_background(value, model=None) -> tuple[float, float, float]:
        r, g, b, _ = _rgba(value, "background")
        return (r, g, b)

    @staticmethod
    @checks("color")
    def check_color(value, model=None) -> ColorStyle:
        return ColorStyle.parse(value)

    def as_dict(self) -> dict:
        """The options as plain JSON-friendly values (for stats and settings)."""
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, CameraSpec | Plane):
                v = dataclasses.asdict(v)
            elif isinstance(v, ColorStyle):
                v = {k: getattr(v, k) for k in ("colormap", "range", "log", "reverse", "solid",
                                                "nan_color", "categorical")}
            elif isinstance(v, np.ndarray):
                v = v.tolist()
            out[f.name] = v
        return out


derive_tables(ViewOptions, ViewOptions, VIEWS)
ViewOptions._CHECKS = bind_checks(ViewOptions, base=True, shorthands=SHORTHANDS)

__all__ = [
    "CAMERA_JSON",
    "CAMERA_KEYS",
    "COLOR_KEYS",
    "VIEWS",
    "CameraSpec",
    "ColorStyle",
    "Plane",
    "SavedCamera",
    "ViewOptions",
    "check_bool",
    "check_choice",
    "check_exaggeration",
    "check_number",
    "check_range",
    "checks",
]
