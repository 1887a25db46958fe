"""Options of the digital-core View (checked before any GL context exists)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar

from geoshade.compute.voxels.roi import parse_roi
from geoshade.compute.voxels.selection import check_range as check_value_range
from geoshade.core.preview import preview_level
from geoshade.core.values import SAMPLE_MODES, auto_select, is_auto, region
from geoshade.errors import InputError
from geoshade.models.volume import VoxelVolume
from geoshade.scheduler import require_cluster
from geoshade.styles.checks import parse_bytes
from geoshade.styles.declare import option
from geoshade.styles.light import Occlusion
from geoshade.styles.options import ColorStyle, check_bool, check_choice, check_number, checks
from geoshade.styles.shared_options import (
    CULL,
    ClusterOptions,
    ColorOptions,
    ExaggerationOptions,
    MemoryOptions,
    ProgressiveOptions,
)

#: the methods a user may ask for; ``auto`` is resolved per renderer by :func:`resolve_method`
METHODS = ("auto", "raycast", "trefoil", "gs", "cubes")

#: what ``auto`` picks. Measured with ``geoshade bench core`` (benchmarks/RESULTS.md): on the
#: software rasteriser (llvmpipe) the ray caster re-renders 256³ 20-40× faster
#: than any rasterised method, because all geometry stages run on one thread there. On hardware
#: GPUs the ray caster is kept too (no tessellation/GS amplification, 1.15 B/voxel) until a
#: benchmark on a GPU says otherwise.
AUTO = {"software": "raycast", "hardware": "raycast"}
#: trefoil selection: per voxel from the eye (default) or the paper's Eq. (1)
TREFOIL_MODES = ("eye", "paper")
#: axes of the porosity profile
AXES = ("x", "y", "z")


def resolve_method(method: str, software: bool) -> str:
    """The method ``auto`` stands for on this renderer (others as they are).

    >>> resolve_method("auto", software=True), resolve_method("gs", software=False)
    ('raycast', 'gs')
    """
    method = check_choice(method, METHODS, "method")
    if method == "auto":
        return AUTO["software" if software else "hardware"]
    return method


def default_select(volume: VoxelVolume) -> tuple[float, float]:
    """The selection when none is given: ``meta['pore_range']`` where the file says, else the
    whole range of an integer dtype; float data needs an explicit one."""
    pr = (volume.meta or {}).get("pore_range")
    if pr is not None:
        return float(pr[0]), float(pr[1])
    lo, hi = volume.value_limits()
    if lo == float("-inf"):
        raise InputError(f"{volume.name or 'volume'}: float data needs an explicit selection "
                         "(--select LO HI, select=(lo, hi))")
    return lo, hi


@dataclass(frozen=True)
class CoreOptions(ExaggerationOptions, ColorOptions, ClusterOptions, ProgressiveOptions,
                  MemoryOptions):
    """Options of :class:`~geoshade.core.CoreView`.

    select:  (lo, hi) values selected, inclusive, in the data's units (default: ``pore_range``
             of the file, else the dtype's whole range); the old name ``range`` still works
    box:     sub-volume ``[x0, y0, z0, nx, ny, nz]`` or a Box (default: the whole volume, in
             every front end)
    method:  ``auto raycast trefoil gs cubes``
    color:   :class:`ColorStyle`; its range is the values spread over the colour map (default:
             the selection); shorthands ``colormap``, ``color_range``, ``palette``
    cull:    skip hidden voxels (rasterised methods; default on)
    trefoil_mode: ``eye`` (exact per voxel) or ``paper`` (Eq. 1, one trefoil per frame)
    gpu_memory: bytes the GPU may hold (``8G``); beyond it the box is drawn in bricks
    bricks:  None (auto: beyond the texture limit or the GPU memory), False (never), True
             (always) or the largest brick side
    scheduler: where the View's dask work runs (:class:`~geoshade.scheduler.Scheduler`): the
             selection maps and porosity with dask, and the cluster drawn on with
             ``distributed``; an address, ``local:N``, a local name or a client
    distributed: draw the box's bricks on the ``scheduler``'s cluster (the same option for the
             grid), composited by depth (:class:`~geoshade.core.distributed.ClusterBricks`);
             ``bricks`` is then the brick side (default: at least four bricks per worker);
             ``worker_timeout``: seconds a worker may take for one call (300)
    porosity: axis (``x y z``) of a porosity profile computed with every selection, or None
    occlusion: ambient occlusion and depth cue over the picture
             (:class:`~geoshade.styles.light.Occlusion`, or True/False, or a dict of its
             fields); None (default): on for a picture in one solid colour (a segmented
             phase), where shading is all that shows the 3D structure, off for a colour map
             (darkening would change the colours the colour bar reads as values)
    exaggeration: vertical exaggeration (z multiplied; e.g. to read thin laminae)
    roi:     region of interest beyond the box: ``"cylinder"`` (a cylinder along z fitted to
             the sample, :func:`geoshade.compute.voxels.roi.fit_cylinder`), ``"cylinder:CX,CY,R"``
             (voxels) or a Cylinder; voxels outside are neither drawn nor counted
    mask:    a mask volume (nonzero = inside): a VoxelVolume, an array or a file name; becomes
             the ``roi`` once parsed with the volume
    sample:  without ``roi``/``mask``: ``"auto"`` (default) draws and counts only the sample
             detected in air (:func:`geoshade.core.detect_sample`; a volume without air, a
             label image: every voxel), as ``core porosity`` counts; ``"none"``: every voxel
             of the box
    select_auto: how an automatic selection (``select="auto"``: the values up to Otsu's
             threshold of the box's voxels inside the ROI) was found; set by parsing
    progressive: a picture at once: draw a coarse preview from the store's overview level
             first (:mod:`geoshade.render.progressive`), then build the full bricks
    """

    select: Any = option(
        None, nargs="+", metavar=("LO|auto", "HI"), group="shown", control="selection",
        example=lambda model=None: (0, 90),
        help="values selected, inclusive, in the data's units (the pore space or the mineral "
             "skeleton); auto: the pore space, the values up to Otsu's threshold of the box's "
             "voxels inside the ROI (default: the pore range the file names, else the whole "
             "dtype range)")   # (lo, hi) floats once parsed with the volume
    box: Any = option(
        None, nargs=6, type=int, metavar=("X0", "Y0", "Z0", "NX", "NY", "NZ"), group="shown",
        example=lambda model=None: (2, 2, 2, 10, 10, 10),
        help="sub-volume: offset and size in voxels (default: the whole volume)")  # a Box
    method: str = option("auto", choices=METHODS, group="method", example="cubes",
                         help="auto picks the fastest for this renderer (raycast on llvmpipe)")
    cull: bool = option(True, **CULL)
    trefoil_mode: str = option(
        "eye", choices=TREFOIL_MODES, group="method", aliases=(("--paper-trefoil", "paper"),),
        control="", example="paper",
        help="trefoil selection: per voxel from the eye (eye) or one trefoil per frame from "
             "the view direction, Eq. (1) (paper; --paper-trefoil)")
    gpu_memory: int | None = option(
        None, live=False, metavar="SIZE", group="cluster", control="",
        help="GPU memory the picture may use (8G, 512M, bytes): a box beyond it is drawn in "
             "bricks (default: what the driver says)")
    bricks: Any = option(
        None, live=False, metavar="N", group="cluster", control="",
        help="draw in bricks of at most N voxels per side (0: never; default: only when the box "
             "exceeds the GPU's texture limit or memory)")
    porosity: str | None = option(
        None, choices=AXES, metavar="AXIS", group="shown", example="x",
        help="the porosity profile along AXIS (x, y or z): the pore fraction in the subtitle "
             "and the stats, the viewers' porosity plot (default: none)")
    occlusion: Any = option(
        None, form="switch", group="picture", example=False,
        help="ambient occlusion and depth cue (default: on for one solid colour, e.g. a single "
             "selected value); --no-occlusion: plain directional lighting only")
    roi: Any = option(
        None, metavar="cylinder[:CX,CY,R]|sample", group="cut", example="cylinder:8,8,6",
        help="only the voxels inside count and are drawn: 'cylinder' fits a cylinder along z "
             "to the sample scanned in air, 'cylinder:CX,CY,R' in voxels, 'sample' the sample "
             "detected in air")   # a Cylinder or MaskRoi once parsed with the volume
    mask: Any = option(
        None, metavar="FILE", group="cut", control="",
        help="a mask volume of the same shape: only voxels where it is nonzero count and are "
             "drawn (a raw mask: one uint8/uint16 per voxel)")  # folded into roi when parsed
    sample: str = option(
        "auto", choices=SAMPLE_MODES, group="cut", example="none",
        help="without --roi/--mask, draw and count only the sample detected in air (auto: its "
             "footprint over the slices; none: every voxel of the box)")
    select_auto: Any = option(None, flag=None, control="", group="shown",
                              help="how an automatic selection was found (set by parsing)")

    PART: ClassVar[str] = "core"
    DEPRECATED: ClassVar[dict] = {"range": ("select", None),
                                  "gpu_memory_limit": ("gpu_memory", None)}
    NO_COLOR: ClassVar[tuple[str, ...]] = ("log",)

    @classmethod
    def parse(cls, model=None, base=None, **kw):
        """:meth:`ViewOptions.parse` (pure and cheap: no voxel is read); numbers given for
        ``select`` drop an earlier automatic selection's ``select_auto``."""


        opts = super().parse(model, base, **kw)
        if ("select" in kw and "select_auto" not in kw and not is_auto(kw["select"])
                and opts.select_auto is not None):
            return dataclasses.replace(opts, select_auto=None)  # no longer Otsu's
        return opts

    def resolve(self, model, progress=None):
        """The data work, once, for every path: the ROI resolved (a cylinder fitted to the
        sample, a mask read) and ``select="auto"`` turned into the values up to Otsu's
        threshold of the box's voxels inside the ROI (:func:`geoshade.core.auto_select`).

        >>> import geoshade
        >>> vol = geoshade.synthetic_core(16, dtype="uint8")
        >>> o = CoreOptions.parse(vol, select="auto")
        >>> o.select, o.resolve(vol).select_auto["method"]
        ('auto', 'otsu')
        """


        if model is None:
            return self
        changes: dict[str, Any] = {}
        roi = self.roi
        if self.defers_sample(model):
            pass   # progressive: found on the preview's level now, on level 0 when refined
        elif roi is None and self.mask is None and self.sample == "auto":
            # drawn = counted: the sample detected in air (None: no air, every voxel)
            roi = region(model, self.box, "sample", progress=progress)[1]
            if roi is not None:
                changes.update(roi=roi)
        elif self.mask is not None or isinstance(roi, str):
            _, roi = region(model, self.box, roi, self.mask, progress=progress)
            changes.update(roi=roi, mask=None)
        if is_auto(self.select):
            sel, how = auto_select(model, self.box, roi, progress=progress)
            changes.update(select=sel, select_auto=how)
        return dataclasses.replace(self, **changes) if changes else self

    def defers_sample(self, model) -> bool:
        """True when a progressive View leaves finding the sample in air (``sample="auto"``)
        to the full picture's build: a store's box big enough for a preview, whose level the
        preview searches instead (:mod:`geoshade.core.preview`)."""
        return bool(self.progressive and self.roi is None and self.mask is None
                    and self.sample == "auto" and model is not None
                    and preview_level(model, self.box) is not None)

    @staticmethod
    @checks("mask")
    def check_mask(value, model=None):
        """A mask volume, an array or a file name; read by :meth:`resolve`."""
        return value

    @staticmethod
    @checks("select_auto")
    def check_select_auto(value, model=None):
        if value is not None and not isinstance(value, dict):
            raise InputError(f"select_auto: set by resolving select='auto', got {value!r}")
        return value

    @staticmethod
    @checks("roi")
    def check_roi(value, model=None):

        return parse_roi(value)

    @staticmethod
    @checks("select")
    def check_select(value, model):

        if value is None:
            return default_select(model) if model is not None else None
        if isinstance(value, list | tuple) and len(value) == 1:   # ["auto"] as typed
            value = value[0]
        if is_auto(value):
            return "auto"
        try:
            lo, hi = value
        except (TypeError, ValueError):
            raise InputError(f"select: expected two numbers LO HI or 'auto' (Otsu), got "
                             f"{value!r}") from None
        return check_value_range(lo, hi, model.dtype if model is not None else None,
                                 name="select")

    @staticmethod
    @checks("box")
    def check_box(value, model):
        return model.resolve_box(value) if model is not None else value

    @staticmethod
    @checks("color")
    def check_color(value, model=None):
        style = ColorStyle.parse(value)
        if style.log:
            raise InputError("color: a log colour scale is not available for voxel volumes "
                             "(their colour index is linear in the values)")
        return style

    @staticmethod
    @checks("porosity")
    def check_porosity(value, model=None):
        """An axis, or None (``"none"``): no porosity profile."""
        if value is None or (isinstance(value, str) and value.strip().lower() == "none"):
            return None
        return check_choice(value, AXES, "porosity")

    @staticmethod
    @checks("gpu_memory")
    def check_gpu_memory(value, model=None):
        return None if value is None else parse_bytes(value, "gpu_memory")

    @staticmethod
    @checks("bricks")
    def check_bricks(value, model=None):
        """None (auto), False (never; ``0`` or ``never`` on a command line), True (always) or
        the largest brick side."""
        if value is None or isinstance(value, bool):
            return value
        if str(value).strip().lower() in ("0", "never", "false", "no"):
            return False
        return check_number(value, "bricks", lo=1, integer=True)  # the largest brick side

    @staticmethod
    @checks("occlusion")
    def check_occlusion(value, model=None):
        if value is None or value is False:
            return value
        if isinstance(value, str):
            value = check_bool(value, "occlusion")
            if not value:
                return False

        return Occlusion.parse(value)

    def validate(self, model) -> None:
        if self.distributed:
            require_cluster(self.scheduler, True, "CoreView")
            if self.bricks is False:
                raise InputError("bricks: distributed rendering draws the box in bricks (give "
                                 "a brick side, or leave --bricks out)")
        if model is None:
            return
        if self.select is None:  # parse() with a model always fills it
            raise InputError("select: expected two numbers LO HI")

    def color_range(self) -> tuple[float, float]:
        """The values spread over the colour map: the colour range, else the selection."""
        if self.color.range is not None:
            return self.color.range
        assert self.select is not None
        return self.select


__all__ = ["AUTO", "AXES", "METHODS", "CoreOptions", "default_select", "resolve_method"]
