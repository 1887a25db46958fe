"""Options of the stacks View (checked before any GL context exists)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from geoshade.compute.stacks import LAYOUTS
from geoshade.errors import InputError, where
from geoshade.models.stacks import EMPTY, StackModel
from geoshade.styles.declare import option
from geoshade.styles.options import Plane, check_number, checks
from geoshade.styles.shared_options import (
    EXAGGERATION,
    PLANE,
    ExaggerationOptions,
    MemoryOptions,
)

#: the largest normal kernel: each lit pixel samples K³ neighbours (9: 729, the paper's
#: largest; 100000 would hold the GPU for hours)
MAX_KERNEL = 15
#: what a user may pass as ``layout`` (``dense``: the dense 3D-texture baseline)
RENDER_LAYOUTS = (*LAYOUTS, "dense")
DEFAULT_LAYOUT = "ssbo"


def check_codes(model: StackModel | None, codes, what: str) -> tuple[int, ...]:
    """Material codes of the model's legend as ints, or one clear error."""
    out = []
    for c in codes or ():
        try:
            ci = int(c)
        except (TypeError, ValueError):
            raise InputError(f"{what}: expected integer material codes, got {c!r}") from None
        if model is not None and model.legend is not None \
                and ci not in set(model.legend.codes.tolist()):
            present = np.unique(model.codes[model.codes != EMPTY]).tolist()
            raise InputError(f"{where(model.name)}{what}: unknown material code {ci}; the "
                             "model has codes "
                             f"{present[:30]}{' …' if len(present) > 30 else ''}")
        out.append(ci)
    return tuple(out)


def opacity_words(items) -> dict[int, float]:
    """``["2010=0.3", ...]`` -> ``{2010: 0.3}``, or one clear error.

    >>> opacity_words(["2010=0.3", "5=1"])
    {2010: 0.3, 5: 1.0}
    """
    out = {}
    for it in items:
        code, sep, val = str(it).partition("=")
        try:
            if not sep:
                raise ValueError
            out[int(code)] = float(val)
        except ValueError:
            raise InputError(f"opacity: expected CODE=A such as 2010=0.3, got {it!r}") from None
    return out


def model_box(model: StackModel) -> np.ndarray:
    """(2, 3) world box of the occupied levels (x, y, z up), without exaggeration."""
    lo_lv, hi_lv = model.occupied_levels()
    og, sp = np.asarray(model.origin), np.asarray(model.spacing)
    return np.stack([og + np.array([0, 0, lo_lv]) * sp, og + np.array([*model.shape, hi_lv]) * sp])


def section_box(model: StackModel) -> np.ndarray:
    """(2, 3) box a section control cuts across: the model's x, y and its occupied z."""
    box = np.array(model_box(model), float)
    box[:, :2] = np.asarray(model.bounds(), float)[:, :2]
    return box


def plane_from_section(section, model) -> Plane:
    """The :class:`Plane` of the deprecated ``section``/``--section``: ``NX,NY,NZ,D`` in world
    coordinates with the side ``n·p > D`` cut away (the new plane keeps the side its normal
    points to, so the normal is reversed).

    >>> plane_from_section("1,0,0,50", None)
    Plane(normal=(-1.0, 0.0, 0.0), offset=-50.0)
    """
    try:
        vals = ([float(v) for v in section.split(",")] if isinstance(section, str)
                else [float(v) for v in np.ravel(section)])
    except (TypeError, ValueError):
        raise InputError(f"section: expected NX,NY,NZ,D numbers, got {section!r}") from None
    if len(vals) != 4 or not np.isfinite(vals).all():
        raise InputError(f"section: expected 4 numbers NX,NY,NZ,D, got {section!r}")
    n = np.asarray(vals[:3])
    length = float(np.linalg.norm(n))
    if not length > 0:
        raise InputError("section: the normal NX,NY,NZ must not be zero")
    return Plane(tuple(float(v) + 0.0 for v in -n / length),  # type: ignore[arg-type]
                 -vals[3] / length)


def index_section(model: StackModel, plane: Plane) -> tuple[float, float, float, float]:
    """The shader's section ``(nx, ny, nz, d)`` in index space: the side ``n·q > d`` of an
    index-space point ``q`` is cut away (what the plane does not keep)."""
    n = -np.asarray(plane.normal)
    d = -float(plane.offset)  # type: ignore[arg-type]
    og, sp = np.asarray(model.origin), np.asarray(model.spacing)
    n_idx = n * sp
    return (*(float(v) for v in n_idx), float(d - n @ og))  # type: ignore[return-value]


@dataclass(frozen=True)
class StacksOptions(ExaggerationOptions, MemoryOptions):
    """Options of :class:`~geoshade.stacks.StacksView`.

    layout:   GPU layout of Section 4.2 (``textures r-supertexels l-supertexels texture3d ssbo``)
              or ``dense`` (the dense 3D-texture baseline)
    walk:     ``exact`` interval walk (default) or the ``paper``'s coarse/fine sampling
    walk_from: ``auto top bottom``
    exaggeration: vertical exaggeration
    kernel:   k of the k×k×k normal kernel (None: adaptive 5..9)
    smooth:   Gaussian smoothing of the colours in pixels (0: off)
    lighting: shade the surfaces
    brick_skip: skip bricks of air
    hide:     material codes not drawn; ``opacity`` {code: 0..1}
    plane:    :class:`Plane` (the old ``section`` still works: it cut away ``n·p > d``)
    boreholes: draw the borehole columns only
    drape:    image on the top surface (path or (h, w, 4) array), ``drape_mix`` 0..1; a
              georeferenced GeoTIFF is placed by its georeference (rasterio), cropped and
              resampled to the model; one that misses the model is an error, one that covers
              part of it a warning with the fraction covered
    top:      ``auto`` (smooth for models made from DEMs), ``smooth`` (the top of the stacks
              interpolated between column centres: terrain, not stairs), ``flat`` (each column's
              flat top, the paper)
    top_normals: shade a smooth top with its interpolated gradient normal (False: the hybrid
              image-space normals of its depth, the paper's)
    legend:   the annotations include the legend of the materials shown
    variable, empty, logs: how a file or labelled volume becomes stacks (see ``convert``)
    """

    exaggeration: Any = option("auto", **EXAGGERATION)
    layout: str = option(DEFAULT_LAYOUT, choices=RENDER_LAYOUTS, group="method",
                         example="textures",
                         help="GPU layout of Section 4.2 (ssbo); dense = the dense 3D-texture "
                              "baseline")
    walk: str = option("exact", choices=("exact", "paper"), group="method", example="paper",
                       help="exact interval walk (default) or the paper's coarse/fine sampling")
    walk_from: str = option("auto", choices=("auto", "top", "bottom"), group="method",
                            example="top", help="where a stack walk starts (auto: the paper's "
                                                "box-equator rule)")
    kernel: int | None = option(None, type=int, metavar="K", group="picture", example=3,
                                limits=(0, MAX_KERNEL),
                                help="normal kernel K×K×K (default: adaptive 5..9; < 3: flat)")
    smooth: float = option(0.8, type=float, metavar="SIGMA", group="picture", example=0.0,
                           limits=(0, 10),
                           help="Gaussian smoothing of the colours, pixels (0.8; 0 = off)")
    lighting: bool = option(True, form="switch", group="picture",
                            aliases=(("--no-light", False),), example=False,
                            help="shade the surfaces (--no-lighting: the transfer colours)")
    brick_skip: bool = option(True, form="switch", group="method", control="",
                              help="skip the bricks of air while walking the rays")
    hide: tuple = option(
        (), nargs="+", metavar="CODE", group="cut", control="materials",
        example=lambda model=None: (int(model.legend.codes[0]),) if model is not None else (),
        help="material codes to hide")
    opacity: Any = option(
        None, nargs="+", metavar="CODE=A", group="cut", control="materials",
        example=lambda model=None: ({int(model.legend.codes[-1]): 0.4} if model is not None
                                    else None),
        help="attenuate materials: opacity 0..1 per code")
    plane: Plane | None = option(None, **{**PLANE, "control": "section"})
    boreholes: bool = option(False, form="switch", group="shown", example=True,
                             help="draw the borehole logs only")
    drape: Any = option(None, metavar="IMAGE", group="shown", control="drape",
                        help="PNG/JPEG/GeoTIFF on the top surface (a GeoTIFF is placed by its "
                             "georeference)")
    drape_mix: float = option(1.0, type=float, metavar="A", group="picture", example=0.5,
                              limits=(0, 1),
                              help="how much of the drape shows over the materials' colours, "
                                   "0..1 (1)")
    top: str = option(
        "auto", choices=("auto", "smooth", "flat"), flag="--top-mode", group="method",
        example="flat",
        help="the top of the stacks: smooth (interpolated between column centres: terrain), "
             "flat (each column's flat top, the paper); auto: smooth for models made from DEMs")
    top_normals: bool = option(
        True, form="switch", group="picture", aliases=(("--hybrid-normals", False),),
        control="", example=False,
        help="shade a smooth top with its interpolated gradient (--hybrid-normals: the paper's "
             "hybrid image-space normals)")
    legend: bool = option(True, form="switch", group="picture", example=False,
                          help="the legend of the materials shown (with the annotations)")
    variable: str | None = option(None, flag=None, control="", group="shown",
                                  help="netCDF variable of a file converted to stacks")
    empty: Any = option(None, flag=None, control="", group="shown",
                        help="label value meaning empty in a converted labelled volume")
    logs: Any = option("auto", flag=None, control="", group="shown",
                       help="borehole logs placed into a converted model's columns")

    PART: ClassVar[str] = "stacks"

    def resolve(self, model, progress=None):
        """``exaggeration="auto"`` decided from the occupied levels' box (the one rule of every
        front end)."""
        if not isinstance(model, StackModel):
            return self
        return self.resolve_exaggeration(model_box(model))

    @staticmethod
    @checks("variable")
    def check_variable(value, model=None):
        """The variable of a file converted to stacks (e.g. GeoTOP's ``lithok``)."""
        if value is None or value == "":
            return None
        if not isinstance(value, str):
            raise InputError(f"variable: expected a variable name, got {value!r}")
        return value

    @staticmethod
    @checks("empty")
    def check_empty(value, model=None):
        """The value of empty voxels of a labelled volume converted to stacks (None: NaN/0)."""
        return check_number(value, "empty", allow_none=True)

    @staticmethod
    @checks("logs")
    def check_logs(value, model=None):
        """Borehole logs beside a converted file: ``auto``, a file, ``none`` (see ``convert``)."""
        if value is not None and not isinstance(value, str | Path | bool):
            raise InputError(f"logs: expected auto, none or a file, got {value!r}")
        return value
    DEPRECATED: ClassVar[dict] = {"section": ("plane", plane_from_section)}

    @staticmethod
    @checks("kernel")
    def check_kernel(value, model=None):
        return check_number(value, "kernel (< 3: flat)", lo=0, hi=MAX_KERNEL, integer=True,
                            allow_none=True)

    @staticmethod
    @checks("smooth")
    def check_smooth(value, model=None):
        return check_number(value, "smooth (pixels)", lo=0)

    @staticmethod
    @checks("hide")
    def check_hide(value, model=None):
        return check_codes(model, [value] if isinstance(value, str | int) else value, "hide")

    @staticmethod
    @checks("opacity")
    def check_opacity(value, model=None):
        if not value:
            return None
        if isinstance(value, str | list | tuple):   # "CODE=A" words as typed
            value = opacity_words([value] if isinstance(value, str) else value)
        if not isinstance(value, dict):
            raise InputError(f"opacity: expected {{code: 0..1}}, got {value!r}")
        codes = check_codes(model, list(value), "opacity")
        return {c: check_number(a, f"opacity: code {c}", 0, 1)
                for c, a in zip(codes, value.values(), strict=True)}

    @staticmethod
    @checks("plane")
    def check_plane(value, model=None):
        p = Plane.parse(value)
        if p is None or model is None:
            return p
        box = model_box(model)
        p = p.resolve(box.mean(axis=0))
        if not p.crosses(box):
            lo, hi = box
            raise InputError(
                f"plane: {p.text()} misses the model (x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}.."
                f"{hi[1]:g}, z {lo[2]:g}..{hi[2]:g}); it must cross the box")
        return p

    @staticmethod
    @checks("drape")
    def check_drape(value, model=None):
        if value is None or value is False:
            return None
        if isinstance(value, str | Path):
            from geoshade.io.layers.dem import is_georeferenced

            if is_georeferenced(value):
                # the header only: no overlap is an error, a partial one warns (once, here)
                if model is not None:
                    drape_on_model(value, model, check_only=True)
                else:
                    from geoshade.io.layers.dem import drape_header

                    drape_header(value)
                return value
            from geoshade.io.volumes.image import probe_image

            probe_image(value)  # the header only: a file that is no image fails here
            return value
        img = np.asarray(value)
        if img.ndim != 3 or img.shape[2] != 4:
            raise InputError(f"drape: expected an (h, w, 4) RGBA image, got shape {img.shape}")
        return img

    @staticmethod
    @checks("drape_mix")
    def check_drape_mix(value, model=None):
        return check_number(value, "drape_mix", 0, 1)


def drape_on_model(path, model: StackModel, check_only: bool = False):
    """A georeferenced drape on ``model``'s grid (:func:`geoshade.io.layers.dem.drape_for`):
    ``(rgba covering the grid, fraction covered)``."""
    from geoshade.io.layers.dem import drape_for

    nx, ny = model.shape
    return drape_for(path, model.origin[:2], model.spacing[:2], (nx, ny), model.crs,
                     check_only=check_only)


__all__ = ["DEFAULT_LAYOUT", "RENDER_LAYOUTS", "StacksOptions", "check_codes", "drape_on_model",
           "index_section", "model_box", "plane_from_section"]
