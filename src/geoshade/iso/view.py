"""``IsoView``: a live isosurface of a field over time (tessellation marching cubes)."""

from __future__ import annotations

import concurrent.futures
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.compute.mesh import marching_cubes as mc
from geoshade.compute.mesh.displacement import displacement_field
from geoshade.io.interop.mesh import write_mesh
from geoshade.iso.api import (
    OutsideValuesWarning,
    PreparedStep,
    choose_slice_axis,
    empty_reason,
    field_of,
    geometry,
    prepare_step,
    prepare_step_property,
    refined_hosts_hidden,
    world_bounds,
)
from geoshade.iso.diff import DELTA, assumed_level, diff_stats, difference_field, steps_text
from geoshade.iso.keyword import keywords, rekeyed
from geoshade.iso.options import METHOD, IsoOptions, field_reports, with_color_by
from geoshade.iso.refined import SEAM_NOTE, RefinedSurfaces, merged
from geoshade.models.field import FieldSeries, TriangleMesh
from geoshade.models.grid import CornerPointGrid
from geoshade.models.steps import step_caption, step_label
from geoshade.render.view import Job, View, fmt_int
from geoshade.styles.annotate import ColorBar, Legend, exaggeration_text, join_subtitle
from geoshade.styles.categories import (
    by_name,
    categorical_palette,
    distinct_codes,
    is_categorical,
    legend_entries,
)
from geoshade.styles.difference import color_name, diverging, symmetric_range
from geoshade.styles.shading import shading_uniforms
from geoshade.styles.units import case_unit_system, length_unit, value_unit


class IsoView(View[IsoOptions]):
    """A live view of the isosurface ``S = level`` of a field, step by step.

    Only what changed is redone: a new camera re-draws the triangles captured when the surface
    was last marched (mesh cache), a new level marches once on the GPU; a new step goes into the
    back one of two slots, then swaps. After a step's frame, the next one is read and prepared
    in a background thread and marched into the back slot's captured mesh, so stepping forward
    is a swap. With the mesh cache the field is marched in slabs of slices through one small
    texture (the slots hold captured meshes, not whole fields; the visual asks ``_refill`` for a
    slot's arrays when it marches it); without it (the paper's every-frame march) each slot
    holds its whole field.

    Parameters
    ----------
    field : FieldSeries or CornerPointGrid
        A grid is shown by its ``keyword`` option (default SWAT) over its report steps.
    level : float, optional
        ``S*`` (also an option by name); default the middle of the initial step's values.
    **options
        :class:`~geoshade.iso.options.IsoOptions`: ``step``, ``color_by``, ``colormap``/
        ``color_range``/``color``, ``patch_level``, ``skip_patches``, ``slice_axis``,
        ``prefetch``, ``exaggeration``, ``mesh_cache``, ``caps`` (close the surface along
        inactive cells; default open) ...

    Examples
    --------
    >>> from geoshade.compute.mesh.displacement import displacement_field
    >>> f = displacement_field((24, 16, 16), steps=3)
    >>> with IsoView(f, 0.5, step=0, size=(64, 48)) as view:
    ...     img, stats = view.draw()
    ...     view.update(step=1)
    ...     img, stats1 = view.draw()
    >>> stats["step"], stats1["step"], stats1["triangles"] > 0
    (0, 1, True)
    """

    kind = "iso"
    title = "saturation isosurface"
    Options = IsoOptions
    model_types = (FieldSeries,)
    has_exaggeration = True
    count_in_frame = True

    options: IsoOptions
    visual: Any
    color_range: Any
    _first: Any
    _slots: list[Any]

    def __init__(self, field, level=None, **kw):
        if level is not None:
            kw["level"] = level
        super().__init__(field, **kw)

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, FieldSeries | CornerPointGrid)

    @classmethod
    def coerce(cls, model, options: dict, progress=None):
        if isinstance(model, CornerPointGrid):
            return field_of(model, options.get("keyword"), options.get("color_by"))
        if isinstance(model, FieldSeries):  # loaded without the colouring quantity
            model = refined_hosts_hidden(with_color_by(model, options.get("color_by")))
        return super().coerce(model, options, progress)

    @classmethod
    def demo(cls):

        field = displacement_field((64, 48, 48), steps=8, seed=0)
        return field, {"level": 0.5, "step": 5, "color_by": "PRESSURE"}

    # --- set-up ----------------------------------------------------------------------------------
    def _setup(self) -> None:
        from geoshade.render.visuals.isosurface.visual import BASE_COLOR, IsoSurfaceVisual

        o = self.options
        if not hasattr(self, "level_given"):
            #: the level was given (at opening or by ``update``), not assumed
            self.level_given = o.level is not None
        self.field = field = self._shown_field()
        self.model_matrix, positions = geometry(field, o.exaggeration)
        self.shading = shading_uniforms()
        self.base_color = o.color.solid if o.color.solid is not None else BASE_COLOR
        first = o.step
        pv0 = mc.prepare_values(field.step(first), field.active)
        #: what was assumed of the level (a change's, said in the stats and the picture)
        self.level_note = None
        if o.level is None and o.diff is not None:   # a change: half its largest, said
            level = assumed_level(pv0.vmin, pv0.vmax)
            self._set(level=level)
            self.level_note = (
                f"level {field.name} = {level:g} assumed: half the largest change of "
                f"{steps_text(field, first, o.diff)} ({field.name} from {pv0.vmin:.3g} to "
                f"{pv0.vmax:.3g} on the active cells); give --level (level=) to choose"
                if pv0.vmin is not None else
                f"level {field.name} = 0 assumed: no active finite node; give --level (level=)")
        elif o.level is None:  # the middle of the initial step's values
            mid = 0.5 if pv0.vmin is None or pv0.vmax is None else 0.5 * (pv0.vmin + pv0.vmax)
            self._set(level=float(mid))
        computed: dict = {}   # the chosen axis's patch ranges, not computed twice
        self.slice_axis = choose_slice_axis(pv0, self.options.level, o.patch_level,
                                            o.slice_axis, o.caps, keep=computed)
        self.color_range = None
        self._resolve_style(first)
        self._first = self._with_log(prepare_step(field, first, o.patch_level, o.color_by,
                                                  self.slice_axis, prepared=pv0, caps=o.caps,
                                                  ranges=computed.get(self.slice_axis)))
        self._palette_bytes = self._palette().tobytes()
        self.visual = IsoSurfaceVisual(self.ctx, field.shape, patch_level=o.patch_level,
                                       skip_patches=o.skip_patches, positions=positions,
                                       palette=self._palette(),
                                       slice_axis=self.slice_axis, mesh_cache=o.mesh_cache,
                                       caps=o.caps, refill=self._refill)
        self._slots: list[PreparedStep | None] = [None, None]
        self._executor = (concurrent.futures.ThreadPoolExecutor(1, "geoshade-iso-prefetch")
                          if o.prefetch and field.nsteps > 1 else None)
        self._future: tuple[int, concurrent.futures.Future] | None = None
        self.switch_ms = 0.0
        self.swapped = False
        #: the last step switch found the new step's triangles captured ahead (no march)
        self.premarched = False
        self._show_step(first)
        self._reset_color_range()
        grid = field.grid
        #: the surfaces of local grid refinements, drawn inside their hosts (iso/refined.py)
        self.refined = RefinedSurfaces(self) if grid is not None and grid.refinements \
            else None

    def _shown_field(self) -> FieldSeries:
        """The field drawn: the model's, or its change since step ``diff``
        (:func:`~geoshade.iso.diff.difference_field`, made once per model and step)."""
        diff = self.options.diff
        if diff is None:
            return self.model
        key = (id(self.model), diff)
        held = getattr(self, "_diff_field", None)
        if held is None or held[0] != key:
            held = self._diff_field = (key, difference_field(self.model, diff))
        return held[1]

    def differenced(self, name: str | None) -> bool:
        """True when quantity ``name`` is drawn as its change (``diff``: the report-step
        quantities; static ones are drawn as they are)."""
        return self.options.diff is not None and name is not None and \
            name in (self.field.meta or {}).get("differenced", ())

    @property
    def level(self) -> float:
        return float(self.options.level)

    @property
    def color_by(self) -> str | None:
        return self.options.color_by

    @property
    def patch_level(self) -> int:
        return self.options.patch_level

    @property
    def exaggeration(self) -> float:
        return self.options.exaggeration

    @property
    def z_scale(self) -> float:  # the old name
        return self.options.exaggeration

    # --- steps ---------------------------------------------------------------------------------
    @property
    def step(self) -> int:
        return self._slots[self.visual.front].step

    @property
    def nsteps(self) -> int:
        return self.field.nsteps

    @property
    def info(self) -> PreparedStep:
        """What the shown step's preparation found (range, NaN count, times)."""
        return self._slots[self.visual.front]

    def _resolve_style(self, step: int) -> None:
        """The colour style with ``log`` decided (a permeability-like ``color_by`` spanning more
        than three decades: log, :meth:`ColorStyle.resolved`)."""


        o = self.options
        self.categories = None   # codes drawn one colour each (a CategoricalPalette)
        if self.differenced(o.color_by):   # a change: diverging, linear, never classes
            self.style, self.log_auto = diverging(o.color), False
            return
        sample = (self.field.property_step(o.color_by, step) if o.color_by is not None
                  else np.zeros(1))
        self.style, self.log_auto = o.color.resolved(o.color_by or "", sample)
        c = o.color
        if o.color_by is None or c.solid is not None or c.palette is not None or \
                c.categorical is False or (c.categorical is None and c.range is not None):
            return
        v = np.asarray(sample)
        if not (c.categorical or by_name(o.color_by) or np.issubdtype(v.dtype, np.integer)):
            return
        active = self.field.active
        codes = distinct_codes(v, active if active is not None and
                               np.shape(active) == v.shape else None)
        if is_categorical(o.color_by, v, c.categorical, codes=codes):

            self.categories = categorical_palette(codes)
            self.style, self.log_auto = replace(self.style, log=False), False

    def _palette(self) -> np.ndarray:
        """The palette the surface is drawn with: the categories' or the colour style's."""
        cat = getattr(self, "categories", None)
        if cat is not None:
            return cat.palette
        if self.differenced(self.options.color_by):
            return diverging(self.options.color).palette_rgba()
        return self.options.color.palette_rgba()

    def _with_log(self, prep: PreparedStep) -> PreparedStep:
        if prep.prop is not None and self.style.log:
            prep.prop = self.style.transform(prep.prop).astype(np.float32)
            bad = ~np.isfinite(prep.prop)
            if bad.any():
                fill = float(prep.prop[~bad].min()) if (~bad).any() else 0.0
                prep.prop[bad] = fill
        return prep

    def _reset_color_range(self) -> None:
        o = self.options
        pal = self._palette()
        if pal.tobytes() != self._palette_bytes:
            self.visual.set_palette(pal)
            self._palette_bytes = pal.tobytes()
        self.visual.categorical = self.categories is not None   # one code per triangle
        if o.color_by is None:
            self.color_range = None
        elif self.categories is not None:
            self.color_range = (self.categories.lo, self.categories.hi)
        elif o.color.range is not None:
            self.color_range = o.color.range
        elif self.differenced(o.color_by):   # centred on 0: the largest change on active nodes
            pv = mc.prepare_values(self.field.property_step(o.color_by, self.step),
                                   self.field.active)
            self.color_range = symmetric_range(pv.vmin, pv.vmax)
        else:
            prop = self.field.property_step(o.color_by, self.step)
            self.color_range = self.style.default_range(prop)

    def _prepare(self, k: int) -> PreparedStep:
        if self._first is not None and self._first.step == k:
            prep, self._first = self._first, None
            return prep
        o = self.options
        return self._with_log(prepare_step(self.field, k, o.patch_level, o.color_by,
                                           self.slice_axis, caps=o.caps))

    def _refill(self, slot: int) -> tuple[np.ndarray, np.ndarray | None]:
        """The field (and colour property) of the step in ``slot`` again, for the visual: with
        the mesh cache it holds one slot's field on the GPU at a time and asks for the other's
        when that slot must be marched anew (a level or colour change on it, a capture)."""
        k = self._slots[slot].step
        values = mc.prepare_values(self.field.step(k), self.field.active).values
        prop = None
        if self.visual.slot_has_property[slot] and self.options.color_by is not None:
            prop = self._with_log(PreparedStep(k, None, None, prepare_step_property(
                self.field, self.options.color_by, k), None, None, 0, 0, 0.0)).prop
        return values, prop

    def _upload(self, prep: PreparedStep, slot: int) -> None:
        self.visual.upload(prep.values, prep.ranges, prep.prop, slot=slot)
        # the slot keeps the small facts, not the arrays (they live on the GPU now)
        self._slots[slot] = PreparedStep(prep.step, None, prep.ranges, None, prep.vmin,
                                         prep.vmax, prep.nonfinite, prep.inactive,
                                         prep.prepare_ms)

    def _service_prefetch(self, wait: bool = False) -> None:
        """Upload a finished background preparation into the back slot."""
        if self._future is None:
            return
        k, fut = self._future
        if not (wait or fut.done()):
            return
        self._future = None
        prep = fut.result()
        front = self.visual.front
        back = 1 - front
        if self._slots[front] is not None and self.step == k:
            return
        if self.empty_reason() is None and self._slots[front] is not None:
            # the shown surface captured first (its frame draws it): the upload into the back
            # slot frees the front's field, one field on the GPU at a time
            self.visual.premarch(front, self.level, self._crange())
        self._upload(prep, back)

    def _premarch_back(self) -> None:
        """March the step prepared ahead in the back slot (no drawing) once a surface size is
        known: the switch to it then draws captured triangles. Only the next step (what the
        prefetch prepares): the step left behind in the back slot is not marched again after
        a level change (a level slider would march twice a frame)."""
        back = 1 - self.visual.front
        nxt = self._slots[back]
        if nxt is not None and nxt.step == self.step + 1 and self.empty_reason() is None:
            self.visual.premarch(back, self.level, self._crange())

    def _schedule(self, k: int) -> None:
        if self._executor is None or not 0 <= k < self.field.nsteps:
            return
        if any(s is not None and s.step == k for s in self._slots):
            return
        if self._future is not None:
            if self._future[0] == k:
                return
            self._future[1].cancel()
            self._future = None
        self._future = (k, self._executor.submit(self._prepare, k))

    def _show_step(self, k: int) -> None:
        t0 = time.perf_counter()
        front = self.visual.front
        self.swapped = False
        if self._future is not None and self._future[0] == k:
            self._service_prefetch(wait=True)
        cur = self._slots[front]
        if cur is None or cur.step != k:
            back = 1 - front
            if self._slots[back] is None or self._slots[back].step != k:
                self._upload(self._prepare(k), back)
            else:
                self.swapped = True
            self.visual.use_slot(back)
        self.premarched = self.swapped and self.visual.has_mesh(self.visual.front, self.level,
                                                                 self._crange())
        self.ctx.finish()
        self.switch_ms = (time.perf_counter() - t0) * 1000
        self._set(step=k)   # the next step is prepared after this step's frame (draw)

    def wait_prefetch(self) -> None:
        """Block until the step prepared ahead (if any) is uploaded into the back slot and
        its surface marched (the step switch then draws captured triangles)."""
        self._service_prefetch(wait=True)
        self._premarch_back()

    def _recolor(self) -> None:
        """The shown step's colour property again (new color_by or log); the prepared-ahead
        step is prepared again."""
        front = self.visual.front
        self._slots[1 - front] = None
        if self._future is not None:
            self._future[1].cancel()
            self._future = None
        info = self._slots[front]
        prop = None
        o = self.options
        if o.color_by is not None:
            prop = prepare_step_property(self.field, o.color_by, info.step)
            prop = self._with_log(PreparedStep(info.step, None, None, prop, None, None, 0, 0,
                                               0.0)).prop
        self.visual.set_property(prop, front)
        self._schedule(info.step + 1)

    # --- changes ---------------------------------------------------------------------------------
    def jobs(self, **changes) -> list[Job]:
        """As every View's; a new ``keyword`` first makes the field of that quantity of the same
        file (:mod:`geoshade.iso.keyword`) and resets what belonged to the old one unless given
        in the same change (level assumed again, the default step, no ``diff``, a colour
        quantity the new field lacks)."""
        kw = changes.get("keyword")
        if kw is None:
            return super().jobs(**changes)
        if str(kw).upper() == str(self.model.name).upper():   # the quantity shown: no change
            return super().jobs(**{k: v for k, v in changes.items() if k != "keyword"})
        color_by = changes.get("color_by", self.options.color_by)
        model = rekeyed(self.model, kw, color_by)
        reset: dict = {"level": None, "step": None, "diff": None}
        if color_by is not None and "color_by" not in changes and str(color_by).upper() not in {
                n.upper() for n in keywords(model)}:
            reset["color_by"] = None
        old = self.model
        self.model = model
        try:
            return super().jobs(**{**reset, **changes, "keyword": model.name})
        except Exception:
            self.model = old
            raise

    def _apply_options(self, new: IsoOptions, changed: set[str]) -> list[Job]:
        old = self.options
        remake = {"patch_level", "skip_patches", "slice_axis", "prefetch", "mesh_cache",
                  "exaggeration", "keyword", "caps", "diff"} & changed
        if "level" in changed:   # None: assumed again
            self.level_given, self.level_note = new.level is not None, None
        elif "diff" in changed and not self.level_given:
            new = replace(new, level=None)   # assumed again, as opening with it assumes it
        if new.color_by is not None and new.color_by not in self.model.properties:
            # a quantity of the file not read when the View opened: read now, every step
            self.model = with_color_by(self.model, new.color_by)
            remake = remake or ({"diff"} if new.diff is not None else set())
            if new.diff is None:
                self.field = self.model
        self.options = new
        if remake:
            self._release_part_objects()
            self._setup()
            return []
        if "step" in changed and new.step != self.step:
            self._show_step(new.step)
        if "color" in changed and new.color.palette_rgba().tobytes() != \
                old.color.palette_rgba().tobytes():
            self._reset_color_range()   # the new palette (the categories' while categorical)
        if "color" in changed and new.color.solid != old.color.solid:
            from geoshade.render.visuals.isosurface.visual import BASE_COLOR

            self.base_color = new.color.solid if new.color.solid is not None else BASE_COLOR
        recat = new.color.categorical != old.color.categorical or \
            new.color.range != old.color.range
        if new.color_by != old.color_by or new.color.log != old.color.log or recat:
            self._resolve_style(self.step)
            self._recolor()
        if new.color_by != old.color_by or new.color.range != old.color.range or \
                new.color.log != old.color.log or recat:
            self._reset_color_range()
        return []

    # --- drawing -------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        return world_bounds(self.field, self.options.exaggeration)

    def empty_reason(self) -> str | None:
        info, diff = self.info, self.options.diff
        if diff is not None and info.step == diff:
            return (f"the shown step is the step the change is taken from "
                    f"({steps_text(self.field, info.step, diff)}): nothing changed")
        return empty_reason(self.level, info.vmin, info.vmax)

    def _crange(self):
        return self.style.transformed_range(*self.color_range) \
            if self.color_by is not None and self.color_range is not None else None

    def _frame(self, camera, target, count: bool) -> dict:
        refined = self.refined
        if self.empty_reason() is not None and refined is None:
            return {"triangles": 0} if count else {}
        if self.empty_reason() is not None and refined is not None:   # the global cells have
            more = refined.draw(camera, target, count)                # none; refinements may
            return {"triangles": int(more.get("triangles") or 0)} if count else {}
        res = self.visual.draw(camera, self.model_matrix, self.shading, self.level,
                               self._crange(), self.base_color, count=count)
        if self.refined is not None:   # the refinements' surfaces, their triangles added
            more = self.refined.draw(camera, target, count)
            if count:
                res = {**res, "triangles": int(res.get("triangles") or 0) +
                       int(more.get("triangles") or 0)}
        return res if count else {}

    def method_name(self) -> str:
        return METHOD

    def _stats(self, counts: dict) -> dict:

        info, f = self.info, self.field
        reason = self.empty_reason()
        marched = (0 if reason is not None else
                   mc.live_patch_cells(info.ranges, f.shape, self.level, self.patch_level,
                                       self.slice_axis)
                   if self.visual.skip_patches else f.cells)
        o = self.options
        return {
            "cells": int(f.cells), "triangles": counts.get("triangles"),
            "level": self.level, "step": info.step, "time": f.times[info.step],
            "step_label": step_label(info.step, f.times, field_reports(f)),
            "nsteps": f.nsteps, "name": f.name,
            "value_range": [info.vmin, info.vmax], "cells_marched": int(marched),
            "patch_level": self.patch_level, "skip_patches": self.visual.skip_patches,
            "mesh_cache": self.visual.mesh_cache, "slice_axis": self.slice_axis,
            "nonfinite": info.nonfinite, "inactive": info.inactive,
            "step_switch_ms": round(self.switch_ms, 3), "prefetched": self.swapped,
            "premarched": self.premarched,
            "prepare_ms": round(info.prepare_ms, 3), "color_by": self.color_by,
            "color_range": list(self.color_range) if self.color_by and self.color_range
            else None, "log": bool(self.style.log), "log_auto": self.log_auto,
            "exaggeration": o.exaggeration, "caps": o.caps,
            "unit": value_unit(f, self.color_by or f.name),
            "unit_system": case_unit_system(f),
            "categories": (None if self.categories is None
                           else [float(c) for c in self.categories.codes]),
            "colormap": (None if self.color_by is None or self.categories is not None
                         else color_name(self.style)),
            "diff": (None if o.diff is None else diff_stats(f, info.step, o.diff)),
            **self._placement(),
            **({} if self.refined is None else {"refinements": self.refined.stats(),
                                                "refinement_note": SEAM_NOTE}),
        }

    def _placement(self) -> dict:
        """Where the nodes are, as the file placed them: its notes (depth taken as up, uneven
        spacing, a dim chosen, assumptions) and the node spacing (``rectilinear``: the nodes
        at the file's own uneven coordinates)."""
        f = self.field
        out: dict = {"nodes": ("corner-point cells" if f.is_cornerpoint else
                               "rectilinear" if f.is_rectilinear else "regular")}
        notes = [str(n) for n in (f.meta or {}).get("notes") or ()]
        if self.level_note:
            notes.append(self.level_note)
        if notes:
            out["notes"] = notes
        return out

    # --- annotations -----------------------------------------------------------------------------
    def _title(self, stats: dict) -> tuple[str, str]:

        f, o = self.field, self.options
        src = Path(f.source).name if f.source else ""
        name = f"{f.name or 'field'} = {self.level:g}"
        if o.diff is not None:   # a change: both steps named
            name += f", {steps_text(f, stats['step'], o.diff)}"
        title = f"{src} — {name}" if src else name
        ex = join_subtitle(*(str(n) for n in (f.meta or {}).get("notes") or ()),
                           "level assumed (half the largest change)" if self.level_note else "",
                           self.refined.caption() if self.refined is not None else "",
                           exaggeration_text(self.options.exaggeration))
        dated = any(t and not str(t).startswith("step ") for t in f.times)
        if stats["nsteps"] <= 1 and not dated:   # a static field: no time to show
            return title, ex
        return title, join_subtitle(
            step_caption(stats["step"], stats["nsteps"], f.times, field_reports(f)), ex)

    def _color_key(self, stats: dict):

        if self.color_by is None or self.color_range is None:
            rgba = tuple(round(255 * c) for c in self.base_color)
            return Legend("", ((f"{self.field.name or 'field'} = {self.level:g}", rgba),))
        if self.categories is not None:   # one entry per code (names where the case has them)

            grid = self.field.grid
            names = ((grid.meta.get("codes") if grid is not None else None) or {}).get(
                self.color_by)
            return Legend(self.color_by, legend_entries(self.categories, names))
        lo, hi = self.color_range
        label = DELTA + self.color_by if self.differenced(self.color_by) else self.color_by
        return ColorBar(label, lo, hi, self._palette(),
                        unit=value_unit(self.field, self.color_by), log=bool(self.style.log),
                        auto=self.log_auto)

    def _length_unit(self) -> str:

        return length_unit(self.field.length_unit or (self.field.grid.units
                                                       if self.field.grid is not None else ""))

    def _where(self) -> str:
        f, info = self.field, self.info
        return f"{f.name or 'field'} at step {info.step} ({f.times[info.step]})"

    def _empty_reason(self, stats: dict) -> str | None:
        reason = self.empty_reason()
        if reason is None and stats.get("triangles") == 0 and not self.options.caps and \
                (self.info.inactive or self.info.nonfinite):
            reason = (f"no cell whose 8 corners are active and finite crosses level "
                      f"{self.level:g} (the surface is open at inactive, NaN and infinite "
                      "cells; caps=True / --caps closes it there)")
        return None if reason is None else f"{self._where()}: {reason}; nothing to draw"

    def _notes(self, stats: dict):
        info, out = self.info, []
        if self.level_note:
            out.append((self.level_note, UserWarning))
        if info.nonfinite:
            out.append((f"{self._where()}: {info.nonfinite:,} nodes are NaN or infinite; they "
                        "are treated as outside the surface", OutsideValuesWarning))
        return out

    def draw(self, camera=None, **kw):
        out = super().draw(camera, **kw)
        # the step ahead is read and prepared from here on, not while this frame was drawn
        # (two cores: the thread slowed a switch's frame down)
        self._schedule(self.step + 1)
        self._service_prefetch()
        self._premarch_back()
        return out

    def _when(self, stats: dict) -> str:
        """``(DATE)`` of the shown step, or ``(DATE − DATE)`` of a change."""
        if self.options.diff is not None and stats.get("step") is not None:
            return f"({steps_text(self.field, stats['step'], self.options.diff)})"
        return f"({stats.get('time')})"

    def readout(self, stats: dict) -> str:
        tri = stats.get("triangles")
        return (f"{stats.get('name') or 'field'} = {stats.get('level', 0):g} · "
                f"step {stats.get('step')} of {stats.get('nsteps')} {self._when(stats)} · "
                f"{'…' if tri is None else fmt_int(tri)} triangles")

    def summary(self, stats: dict) -> str:
        return (f"{stats['width']}x{stats['height']} {stats['method']}, {stats['name']} = "
                f"{stats['level']:g} at step {stats['step']} of {stats['nsteps']} "
                f"{self._when(stats)}, {stats['triangles']:,} triangles from "
                f"{stats['cells']:,} cells, {stats['frame_ms']:.1f} ms/frame, "
                f"{stats['gpu_bytes'] / 2**20:.2f} MiB on the GPU")

    def level_range(self) -> tuple[float, float]:
        """The finite values of the shown step (a level slider's ends)."""
        info = self.info
        lo, hi = info.vmin, info.vmax
        if lo is None or hi is None or not np.isfinite([lo, hi]).all() or not lo < hi:
            return 0.0, 1.0
        return float(lo), float(hi)

    def color_names(self) -> list[str]:
        """The quantities the surface can be coloured by."""
        return list(self.field.properties)

    # --- mesh ----------------------------------------------------------------------------------
    def mesh(self) -> TriangleMesh:
        """The triangles the GPU emits now, captured by transform feedback, in world coordinates.

        Vertices shared by neighbouring cells are computed bit-identically on the GPU and welded
        here; degenerate triangles (a vertex exactly on a node) are kept, so ``n_faces`` equals
        the GPU's triangle count. Normals point towards lower values (out of the displacing
        fluid); ``values`` holds the colour property when colouring. True geometry: the view's
        exaggeration is not applied.
        """
        from geoshade.render.visuals.isosurface.visual import CAPTURE_DTYPE

        cap = (self.visual.capture(self.level, self._crange())
               if self.empty_reason() is None else np.zeros(0, CAPTURE_DTYPE))
        pos = np.ascontiguousarray(cap["pos"], dtype=np.float32)
        key = pos.view(np.dtype((np.void, 12))).ravel()
        uniq, first, inverse = np.unique(key, return_index=True, return_inverse=True)
        faces = inverse.reshape(-1, 3).astype(np.int64)
        m = np.diag([1.0, 1.0, 1.0 / self.options.exaggeration, 1.0]) @ self.model_matrix
        verts = pos[first].astype(np.float64) @ m[:3, :3].T + m[:3, 3]
        nrm = np.zeros((len(uniq), 3))
        np.add.at(nrm, inverse.ravel(), cap["normal"].astype(np.float64))
        nrm = nrm @ np.linalg.inv(m[:3, :3])  # covectors: n_world = M^-T n_model
        ln = np.linalg.norm(nrm, axis=1, keepdims=True)
        nrm = np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 0).astype(np.float32)
        values = cap["value"][first] if self.color_by else None
        f = self.field
        name = f"{f.name} = {self.level:g}, step {self.step}"
        mesh = TriangleMesh(verts, faces, normals=nrm, values=values, name=name)
        if self.refined is None or not self.refined.views:
            return mesh
        return merged([mesh, *self.refined.meshes()], name)   # the refinements' too

    def export_mesh(self, path) -> Path:
        """Write :meth:`mesh` to ``path`` (``.ply``, ``.obj`` or ``.stl``), atomically."""

        return write_mesh(path, self.mesh())

    # --- lifetime --------------------------------------------------------------------------------
    def _stop_prefetch(self) -> None:
        ex = getattr(self, "_executor", None)
        if ex is not None:
            if self._future is not None:
                self._future[1].cancel()
            ex.shutdown(wait=True)
            self._executor = None

    def _release_part_objects(self) -> None:
        self._stop_prefetch()
        refined = getattr(self, "refined", None)
        if refined is not None:   # its Views' own GPU objects
            refined.release()
            self.refined = None
        if getattr(self, "visual", None) is not None:
            self.visual.release()
            self.visual = None

    def _gpu_objects(self) -> list:
        return [o for o in (getattr(self, "visual", None), getattr(self, "refined", None))
                if o is not None]

    def _release_part(self) -> None:
        self._stop_prefetch()
        self.visual = None
        self.refined = None


__all__ = ["IsoView"]
