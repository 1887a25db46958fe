"""``CoreView``: a live view of a micro-CT volume's selected voxels (the digital-core part)."""

from __future__ import annotations

import dataclasses
import textwrap
import time
from typing import Any

import numpy as np

from geoshade.compute.voxels.bricks import (
    DEFAULT_TEX_LIMIT,
    check_brick_budget,
    choose_brick_side,
    needs_bricks,
)
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core.backends import (
    BrickedBricks,
    BricksDrawing,
    Look,
    Prepared,
    Selection,
    WholeBricks,
    model_matrix,
)
from geoshade.core.distributed import ClusterBricks
from geoshade.core.options import CoreOptions, resolve_method
from geoshade.core.preview import level_voxels, preview_level, preview_roi, preview_volume
from geoshade.core.sources import VolumeSource, open_source
from geoshade.core.values import (
    CoreColours,
    core_colours,
    detect_sample,
    histogram,
    porosity,
    thresholds,
)
from geoshade.errors import GPUMemoryError
from geoshade.io.paths import mem_available
from geoshade.models.volume import Box, VoxelVolume
from geoshade.render.progressive import (
    REFINE_LABEL,
    Preview,
    Progressive,
    preview_note,
)
from geoshade.render.view import Job, View, cluster_readout, cluster_summary, fmt_int
from geoshade.render.visuals.bricked.visual import gpu_budget, tex_limit
from geoshade.scheduler import Scheduler
from geoshade.styles.annotate import ColorBar, Legend, exaggeration_text
from geoshade.styles.categories import MAX_ENTRIES, code_text, entry_text
from geoshade.styles.light import Occlusion
from geoshade.styles.shading import shading_uniforms
from geoshade.styles.units import length_unit

#: the colour of a single selected value (a segmented image) when none is asked for: sandstone
SOLID_ROCK = "#c8ad86"


class CoreView(Progressive, View[CoreOptions]):
    """A live view of one volume: change the selection, box, method or camera and draw again.

    Only what changed is redone: a new selection or box rebuilds the bit maps and re-uploads
    them (:meth:`prepare_selection` on any thread, :meth:`apply_selection` on the GL thread);
    a new camera just draws. Boxes beyond the GPU's texture limit or memory are drawn in bricks
    (:mod:`geoshade.render.visuals.bricked`), pixel-identical to the unbricked picture.

    The View *uses* a ``source`` of its voxels (:mod:`geoshade.core.sources`: an array in
    memory or a store) chosen at open and a ``drawing`` chosen per box
    (:mod:`geoshade.core.backends`: the whole box in one visual, the box in bricks, or with
    ``distributed=True`` the bricks on the workers of the ``scheduler``'s cluster,
    :class:`~geoshade.core.distributed.ClusterBricks`); a drawing returns the selection it
    made current. The View keeps the options, the palette, the porosity, the annotations and
    the stats.

    Options: see :class:`~geoshade.core.options.CoreOptions` (``select``, ``box``, ``method``,
    ``color`` ...), plus ``size``, the camera and ``transparent``.

    With ``progressive=True`` a box of a store with overview levels beyond
    :data:`~geoshade.core.preview.PREVIEW_VOXELS` is first drawn from an overview level
    (:mod:`geoshade.render.progressive`: :meth:`refine_job` builds the full maps or bricks).

    Examples
    --------
    >>> import geoshade
    >>> vol = geoshade.synthetic_core(16)
    >>> with CoreView(vol, select=(0, 15000), size=(64, 48)) as view:
    ...     img, stats = view.draw()
    ...     view.update(select=(0, 9000))             # new bit maps, same camera framing
    ...     img2, stats2 = view.draw()
    >>> img.shape, stats["voxels_selected"] > stats2["voxels_selected"]
    ((48, 64, 4), True)
    """

    kind = "core"
    title = "digital core"
    Options = CoreOptions
    model_types = (VoxelVolume,)
    has_exaggeration = True

    options: CoreOptions
    source: VolumeSource
    drawing: BricksDrawing | None
    maps: Any
    porosity: Any

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, VoxelVolume) and not (model.meta or {}).get("legend")

    @classmethod
    def demo(cls):

        return synthetic_core(64, porosity=0.2, seed=7), {"porosity": "z"}

    @classmethod
    def prepare_open(cls, model, progress=None, options=None, **kw):
        """The histogram and (for boxes within one texture) the first selection's maps, built
        on any thread; the constructor then only uploads them."""

        model = cls.coerce(model, kw, progress)
        o = cls.opening_options(model, progress, options, **kw)
        o = cls.coloured(model, o)   # the colour range the View draws with (labels, data)
        prepared: dict = {}
        if o.progressive and preview_level(model, o.box) is not None:
            return model, prepared   # the preview first; the full maps in the refine job
        if o.bricks is False or (o.bricks is None and max(o.box.size) <= DEFAULT_TEX_LIMIT
                                 and Scheduler.parse(o.scheduler).in_place):
            lo, hi = o.select
            t0 = time.perf_counter()
            maps = open_source(model).maps(o, progress=progress)
            poro = None
            if o.porosity is not None:

                poro = porosity(model, (lo, hi), box=o.box, axis=o.porosity, roi=o.roi)
                poro.select_auto = o.select_auto
            prepared["selection"] = Prepared(o.box, lo, hi, o.color_range(), maps,
                                             (time.perf_counter() - t0) * 1000, poro)
        return model, prepared

    def histogram(self, progress=None):
        """The volume's histogram (:func:`geoshade.core.histogram`), computed once."""
        if "histogram" not in self.prepared:

            self.prepared["histogram"] = histogram(self.volume, progress=progress)
        return self.prepared["histogram"]

    def thresholds(self, progress=None):
        """Suggested thresholds (Otsu, multi-Otsu) of the box's voxels inside the ROI
        (:func:`geoshade.core.thresholds`), computed once per box and ROI."""
        o = self.options
        cached = self.prepared.get("thresholds")
        if cached is None or cached[0] != o.box or cached[1] is not o.roi:

            cached = (o.box, o.roi, thresholds(self.volume, o.box, o.roi, progress=progress))
            self.prepared["thresholds"] = cached
        return cached[2]

    # --- set-up ----------------------------------------------------------------------------------
    def _setup(self) -> None:
        from geoshade.render.context import is_software

        self.volume = self.model
        self.software = is_software(self.ctx)
        self.method = resolve_method(self.options.method, self.software)
        #: the colour style asked for (its range None: automatic); the options hold it resolved
        self.color_user = self.options.color
        self.colours: CoreColours = self.colours_of(self.volume, self.options)
        self.options = dataclasses.replace(self.options, color=self.colours.style)
        self.palette = self.palette_for(self.options)
        self.shading = shading_uniforms()
        #: where the voxels live; the drawing is chosen per box (:meth:`drawing_kind`)
        self.source = open_source(self.volume, self.work, self.progress)
        self.drawing = None
        self.maps = None
        self.porosity = None
        self.prepare_ms = self.upload_ms = 0.0
        first = self.prepared.pop("selection", None)
        o = self.options
        self.preview = self._open_preview() if o.progressive else None
        if self.preview is not None:
            return   # the full selection is built by refine_job()
        if first is not None and (first.box, (first.lo, first.hi), first.color_range) != (
                o.box, o.select, tuple(o.color_range())):
            first = None  # prepared for other options
        if first is not None:
            self.porosity = first.porosity
        self._rebuild(first)
        if o.porosity is not None and self.porosity is None:

            self.porosity = porosity(self.volume, o.select, box=o.box, axis=o.porosity,
                                     scheduler=self.work, roi=o.roi)
            self.porosity.select_auto = o.select_auto

    @property
    def box(self) -> Box:
        return self.options.box

    # --- progressive: a preview from an overview level first -------------------------------
    def _open_preview(self) -> Preview | None:
        """A preview of the current options from the overview level :func:`preview_level`
        picks (None: no overview level, or a box small enough to draw at once): the same
        selection, colour range and annotations, its voxels scaled to the full box."""
        o = self.options
        k = preview_level(self.volume, o.box)
        if k is None:
            return None
        vol, lbox = preview_volume(self.volume, k, o.box)
        roi = preview_roi(o.roi, o.box, lbox)
        note = preview_note(f"level {k}", 2**k)
        if o.roi is not None and roi is None:
            note += " · mask not applied"
        color = o.color if o.color.range is not None else o.color.with_(range=o.color_range())
        sample = "auto" if o.defers_sample(self.volume) else "none"   # found on the level
        view = CoreView(vol, ctx=self.ctx, options=o, box=lbox, roi=roi, mask=None,
                        sample=sample, porosity=None, progressive=False, scheduler=None,
                        distributed=False, bricks=None, color=color)
        view.preview_note = note
        return Preview(view, k, 2**k, note, lambda v: level_voxels(v, o.box, lbox))

    def refine_job(self) -> Job:
        """A :class:`Job`: the full selection (maps or bricks) of the current options; the
        preview is released when it is applied."""
        return Job(self.refine_key(), REFINE_LABEL, self._prepare_refined, self._apply_refined)

    def _prepare_refined(self, progress=None) -> tuple[Any, Prepared]:
        """CPU half: the sample found on level 0 where the preview deferred it, the maps."""
        o = self.options
        roi = o.roi
        if o.defers_sample(self.volume):
            roi = dataclasses.replace(o, progressive=False).resolve(self.volume, progress).roi
        return roi, self.prepare_selection(progress=progress, roi=roi)

    def _apply_refined(self, result: tuple[Any, Prepared]) -> None:
        roi, prepared = result
        self._drop_preview()
        self._set(roi=roi)
        self.apply_selection(prepared)

    @property
    def visual(self):
        """The visual of a drawing in this process (None on a cluster)."""
        return None if self.drawing is None else self.drawing.visual

    @property
    def select(self) -> tuple[float, float]:
        return self.options.select

    @staticmethod
    def solid_auto(o: CoreOptions) -> bool:
        """A single selected value (a segmented image's phase) with no colour asked for: every
        voxel would get the colour map's first colour; one rock colour reads better."""
        c = o.color
        return (o.select is not None and o.select[0] == o.select[1] and c.solid is None
                and c.palette is None and c.range is None)

    def occlusion(self):
        """The options' occlusion, on by default for a solid colour (see
        :class:`CoreOptions`); its radius defaults to 3 voxels."""

        o = self.options
        occ = o.occlusion
        if occ is None:
            occ = Occlusion() if (o.color.solid is not None or self.solid_auto(o)) else None
        if not occ:
            return None
        radius = occ.radius if occ.radius is not None else 3.0 * float(min(self.volume.spacing))
        return occ, radius

    def palette_for(self, o: CoreOptions) -> np.ndarray:
        """The palette of options ``o`` (:data:`SOLID_ROCK` for a single value, see
        :meth:`solid_auto`; a label image's qualitative colours, one per label)."""
        if self.solid_auto(o):
            return o.color.with_(solid=SOLID_ROCK).palette_rgba()
        if o.color.categorical and o.color.solid is None and o.color.palette is None:
            cats = core_colours(self.volume, o.select, o.box, o.color).categories
            if cats is not None:
                return cats.palette
        return o.color.palette_rgba()

    @classmethod
    def colours_of(cls, model, o: CoreOptions, user=None) -> CoreColours:
        """How options ``o`` colour ``model`` (:func:`geoshade.core.values.core_colours`) with
        the colour style ``user`` asked for (default ``o.color``): a label image as classes,
        else a colour range over the values present inside the selection."""
        c = o.color if user is None else user
        if o.select is None or isinstance(o.select, str) or cls.solid_auto(
                dataclasses.replace(o, color=c)):
            return CoreColours(c, "selection")
        return core_colours(model, o.select, o.box, c)

    @classmethod
    def coloured(cls, model, o: CoreOptions, user=None) -> CoreOptions:
        """``o`` with its colour style resolved by :meth:`colours_of` (its range explicit)."""
        style = cls.colours_of(model, o, user).style
        return o if style == o.color else dataclasses.replace(o, color=style)

    def bricking(self, box: Box):
        """(brick side, budget) when ``box`` is drawn in bricks in this process, else None."""

        o = self.options
        tex = tex_limit(self.ctx)
        budget = gpu_budget(self.ctx, o.gpu_memory)
        if not needs_bricks(box, self.method, tex, budget, o.bricks):
            return None
        side = choose_brick_side(box, self.method, tex, budget, o.bricks)
        if side > tex:
            raise GPUMemoryError(f"bricks: a brick side of {side} exceeds this GPU's 3D texture "
                                 f"limit of {tex}")

        whole = box.offset == (0, 0, 0) and tuple(box.size) == tuple(self.volume.shape_xyz)
        check_brick_budget(box, side, self.method, mem_available(),  # before any brick is made
                           box.nvoxels * self.volume.dtype.itemsize if whole else None)
        return side, budget

    def drawing_kind(self, box: Box) -> str:
        """The drawing ``box`` is drawn with: ``cluster`` (``distributed``), else ``bricked``
        beyond the texture limit or the GPU memory, else ``whole``."""
        if self.options.distributed:
            return "cluster"
        return "whole" if self.bricking(box) is None else "bricked"

    def _drawing_for(self, box: Box) -> BricksDrawing:
        """The current drawing when it is of ``box``'s kind, else a new one (not yet
        current: no GPU object)."""
        kind = self.drawing_kind(box)
        if self.drawing is not None and self.drawing.name == kind:
            return self.drawing
        if kind == "cluster":
            return ClusterBricks(self.work, self.source, self.shading)
        return (BrickedBricks if kind == "bricked" else WholeBricks)(self.ctx, self.source)

    def _look(self) -> Look:
        """The method and palette the drawing draws with (and the bricking of a box drawn in
        bricks here)."""
        bricked = self.drawing is not None and self.drawing.name == "bricked"
        return Look(self.method, self.palette,
                    self.bricking(self.options.box) if bricked else None)

    def _selected(self, sel: Selection | None) -> None:
        """Make what the drawing drew current (None: as it was)."""
        if sel is not None:
            self.maps, self.prepare_ms, self.upload_ms = sel.maps, sel.prepare_ms, sel.upload_ms

    def _rebuild(self, prepared: Prepared | None = None) -> None:
        """Make the current options' selection current on the GPU (maps built if needed), with
        the drawing of the box (a new box may need another)."""
        drawing = self._drawing_for(self.options.box)
        if drawing is not self.drawing:
            if self.drawing is not None:
                self.drawing.release()
            self.drawing = drawing
        self._selected(drawing.apply(self.options, prepared, self._look()))

    # --- changes ---------------------------------------------------------------------------------
    def prepare_selection(self, select=None, box=None, color_range=None, progress=None,
                          range=None, roi=None) -> Prepared:
        """CPU half of a new selection and/or box: check it, build the bit maps and (with the
        ``porosity`` option) the porosity profile. No GL: safe on a worker thread; hand the
        result to :meth:`apply_selection` on the thread that owns the GL context.

        ``range`` is the deprecated name of ``select``; ``roi``: a resolved ROI (the sample a
        progressive View found when refined).
        """
        changes = {k: v for k, v in (("select", select if select is not None else range),
                                     ("box", box), ("color_range", color_range), ("roi", roi))
                   if v is not None}
        o = self.options.replace(self.volume, **changes)
        if color_range is None:   # an automatic colour range follows the selection and box
            o = self.coloured(self.volume, o, self.color_user)
        lo, hi = o.select
        crange = o.color_range()
        t0 = time.perf_counter()
        maps = self._drawing_for(o.box).prepare(o, progress)   # None for bricks
        ms = (time.perf_counter() - t0) * 1000
        poro = None
        if o.porosity is not None:

            poro = porosity(self.volume, (lo, hi), box=o.box, axis=o.porosity,
                            scheduler=self.work, roi=o.roi)
            poro.select_auto = o.select_auto
        return Prepared(o.box, lo, hi, tuple(crange), maps, ms, poro)

    def apply_selection(self, prepared: Prepared) -> None:
        """GL half: make ``prepared`` (from :meth:`prepare_selection`) the current selection."""
        crange = prepared.color_range
        color = self.options.color
        if crange is not None and crange != (prepared.lo, prepared.hi):
            color = color.with_(range=crange)
        self._set(select=(prepared.lo, prepared.hi), box=prepared.box, color=color)
        self.porosity = prepared.porosity
        self._rebuild(prepared)

    def selection_job(self, **changes) -> Job:
        """A :class:`Job` for a new selection/box (CPU half on any thread, GL half after)."""
        return Job("selection", "building bit maps",
                   lambda progress: self.prepare_selection(progress=progress, **changes),
                   self.apply_selection,
                   applies={k: v for k, v in changes.items() if k in ("select", "box")})

    def _apply_options(self, new: CoreOptions, changed: set[str]) -> list[Job]:

        user = self.color_user
        if "color" in changed:   # asked for; a range left as drawn stays automatic
            user = new.color
            if user.range is not None and user.range == self.options.color.range \
                    and self.color_user.range is None:
                user = user.with_(range=None, categorical=self.color_user.categorical)
        self.color_user = user
        self.colours = self.colours_of(self.volume, new, user)
        new = dataclasses.replace(new, color=self.colours.style)
        if self.preview is not None:   # loading: a new preview now, a new full build after
            self.options = new
            self.method = resolve_method(new.method, self.software)
            self.palette = self.palette_for(new)
            if changed <= {"camera", "size", "background", "transparent", "annotations"}:
                return []
            self._drop_preview()
            self.preview = self._open_preview()
            return [self.refine_job()]
        old = self.options
        sel = bool({"select", "box", "porosity", "roi", "mask"} & changed) or (
            "color" in changed and new.color.range != old.color.range)
        # everything but the selection and box is current at once; the job applies those two
        self.options = dataclasses.replace(new, select=old.select, box=old.box)
        remake = bool({"method", "cull", "trefoil_mode"} & changed)
        palette = self.palette_for(new)
        if {"color", "select", "box"} & changed and palette.tobytes() != self.palette.tobytes():
            self.palette = palette
            if not remake and self.drawing is not None:
                self._selected(self.drawing.colours(self.options, self._look()))
        if remake and self.drawing is not None:
            self.method = resolve_method(new.method, self.software)
            self._selected(self.drawing.remake(self.options, self._look()))
        if sel:
            return [self.selection_job(select=new.select, box=new.box)]
        return []

    # --- drawing ---------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        b = self.volume.bounds(self.options.box)
        b[:, 2] *= self.options.exaggeration
        return b

    def _frame(self, camera, target, count: bool) -> dict:
        assert self.drawing is not None, "the View was released"
        return self.drawing.draw(camera, target, count, self.options, self.shading)

    def method_name(self) -> str:
        return self.method

    def _stats(self, counts: dict) -> dict:
        o = self.options
        st = {
            "voxels_selected": int(self.maps.count),
            "exaggeration": o.exaggeration,
            "voxels_drawn": counts.get("voxels_drawn"),
            "triangles": counts.get("triangles"),
            "box": [*o.box.offset, *o.box.size],
            "select": list(o.select),
            "color_range": list(o.color_range()),
            "prepare_ms": round(self.prepare_ms, 3),
            "upload_ms": round(self.upload_ms, 3),
            **(self.drawing.stats() if self.drawing is not None else {}),   # bricks, workers
        }
        if self.method != "raycast":
            st["cull"] = o.cull
        if o.roi is not None:
            st["roi"] = o.roi.to_dict()
        if o.select_auto is not None:
            st["select_auto"] = dict(o.select_auto)
        if self.porosity is not None:
            st["porosity"] = round(float(self.porosity.porosity), 6)
            st["porosity_quantity"] = self.porosity.quantity
        st["colours"] = self.colours.to_dict()   # the colour range's source, a label image's
        st["label_image"] = self.colours.categories is not None
        if self.colours.categories is not None:
            st["categories"] = [float(c) for c in self.categories_shown()]
        found = self.sample_found()
        if found is not None:
            st["sample"] = found.to_dict()   # what the air detection measured, either way
        st["length_unit"] = self._length_unit()
        st["length_unit_assumed"] = not bool(self.volume.unit)
        return st

    # --- what the picture says besides the voxels ---------------------------------------------
    def sample_found(self):
        """What the sample detection found in the box (:func:`geoshade.core.detect_sample`,
        remembered per box) where the options leave it on (``sample="auto"``, no ROI of the
        user's), else None."""
        o = self.options
        if o.sample != "auto" or o.mask is not None or self.preview is not None:
            return None
        found = detect_sample(self.volume, o.box)
        if o.roi is not None and o.roi is not found.roi:
            return None   # the user's ROI
        return found

    def categories_shown(self) -> list[float]:
        """A label image's labels inside the selection (those the picture can show)."""
        cats = self.colours.categories
        if cats is None:
            return []
        lo, hi = self.options.select
        return [float(c) for c in cats.codes if lo <= c <= hi]

    # --- annotations -----------------------------------------------------------------------------
    def _poro_text(self) -> str:
        p = self.porosity
        if p is None:
            return ""
        where = " of the sample" if (p.sample or {}).get("status") == "in air" else ""
        return f" · {p.quantity} {p.porosity:.4f}{where}"

    def _title(self, stats: dict) -> tuple[str, str]:
        """The title, and a subtitle whose lines after the first are what the CLI prints under
        its porosity line (:meth:`~geoshade.compute.voxels.porosity.PorosityResult.notes`: the side
        of
        Otsu's threshold taken as pore and why, what counts as the sample, the air warning)."""

        o = self.options
        lo, hi = o.select
        sel = f"{lo:g}" if lo == hi else f"{lo:g}..{hi:g}"
        if o.select_auto is not None:
            sel += " (Otsu)"
        shown = self.categories_shown()
        what = "values"
        if shown and len(shown) <= 8:   # a label image: the labels the selection takes
            what, sel = ("label", code_text(shown[0])) if len(shown) == 1 else (
                "labels", ", ".join(code_text(c) for c in shown))
        b = o.box
        box = "" if b.size == self.volume.shape_xyz or self.preview_note else \
            f" · box {'×'.join(map(str, b.size))} at {','.join(map(str, b.offset))}"
        # with a porosity its notes say what region counts (and the picture draws): once
        roi = "" if o.roi is None or self.porosity is not None else f" · in {o.roi.text()}"
        if self.porosity is not None:
            notes = self.porosity.notes()
        else:
            notes = [str(o.select_auto["text"])] if (o.select_auto or {}).get("text") else []
            found = self.sample_found()
            if found is not None and found.status in ("in air", "no air"):
                notes.append(found.text())   # what the air detection measured, either way
        if self.colours.note:
            notes.append(self.colours.note)

        ex = exaggeration_text(o.exaggeration)
        counted = "preview voxels" if self.preview_note else "voxels"
        lines = [f"{stats['voxels_selected']:,} {counted}{self._poro_text()}{box}{roi}"
                 + (f" · {ex}" if ex else "")]
        lines += [textwrap.shorten(n, 110, placeholder="…") for n in notes]
        return (f"{self.volume.name or 'volume'} — {what} {sel} selected",
                self._preview_subtitle("\n".join(lines)))

    def _color_key(self, stats: dict):

        o = self.options
        label = str((self.volume.meta or {}).get("variable") or "value")
        if o.color.solid is not None or self.solid_auto(o):
            lo, hi = o.select
            text = f"{label} {lo:g}" if lo == hi else f"{label} {lo:g}..{hi:g}"
            return Legend("", ((text, tuple(int(v) for v in self.palette[0])),))
        cats = self.colours.categories
        if cats is not None:   # a label image: one entry per label shown, with its share
            counts = self.colours.counts or {}
            total = sum(counts.values()) or 1
            entries = tuple((entry_text(f"{code_text(c)}  {100 * counts.get(c, 0) / total:.1f} %"),
                             cats.rgba_of(c)) for c in self.categories_shown()[:MAX_ENTRIES])
            title = label if label != "value" else "label"
            return Legend(title, entries)
        lo, hi = o.color_range()
        if label == "value" and np.issubdtype(np.dtype(self.volume.dtype), np.integer):
            label = "grey value"   # a micro-CT image's attenuation, in the scanner's units
        return ColorBar(label, lo, hi, self.palette, unit="")

    def _length_unit(self) -> str:
        """The length unit of the volume's spacing, or ``voxels (assumed)`` where the file
        names none (the scale bar, picks and stats say so)."""
        return length_unit(self.volume.unit) or "voxels (assumed)"

    def _empty_reason(self, stats: dict) -> str | None:
        if self.maps.count:
            return None
        lo, hi = self.options.select
        return (f"empty selection: no voxel of box {stats['box']} has a value in "
                f"[{lo:g}, {hi:g}]; the picture is an empty scene")

    def readout(self, stats: dict) -> str:
        poro = self._poro_text()
        drawn = stats.get("voxels_drawn")
        return (f"{fmt_int(stats.get('voxels_selected'))} voxels selected · "
                f"{'…' if drawn is None else fmt_int(drawn)} drawn{poro}"
                + cluster_readout(stats))

    def summary(self, stats: dict) -> str:
        return (f"{stats['width']}x{stats['height']} {stats['method']}, "
                f"{stats['voxels_selected']} voxels selected, {stats['voxels_drawn']} drawn, "
                f"{stats['frame_ms']:.1f} ms/frame, {stats['gpu_bytes'] / 2**20:.2f} MiB on "
                "the GPU" + cluster_summary(stats, "bricks"))

    def _notes(self, stats: dict) -> list[tuple[str, type[Warning]]]:
        return [*super()._notes(stats), *(self.drawing.notes() if self.drawing else [])]

    # --- lifetime --------------------------------------------------------------------------------
    def _gpu_objects(self) -> list:
        drawing = getattr(self, "drawing", None)
        preview = getattr(self, "preview", None)
        return [o for o in (drawing, preview.view if preview is not None else None)
                if o is not None]

    def _release_part(self) -> None:
        self.drawing = None
        self.preview = None


__all__ = ["CoreView", "Prepared", "model_matrix"]
