"""Saturation-isosurface part adapter: level, time step (the front end plays them), colour-by
(forwarded to :class:`geoshade.iso.IsoView`, which prepares the next step in the background)."""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError
from geoshade.models.field import FieldSeries
from geoshade.viewer.parts.base import Job, Part, fmt_int, unknown_settings


class IsoPart(Part):
    """The isosurface view of a :class:`FieldSeries`.

    Settings: ``level`` (S*), ``step`` (0-based), ``color_by`` (a ``field.properties`` name or
    None).
    """

    kind = "iso"
    title = "saturation isosurface"

    def __init__(self, field: FieldSeries, size=(800, 600), level=0.5, step=None,
                 color_by=None, ctx=None):
        if not isinstance(field, FieldSeries):
            raise InputError(f"field: expected a FieldSeries, got {type(field).__name__}")
        self.field, self.ctx = field, ctx
        self._size = size
        self.view = None
        self._make(level, step, color_by)

    def _make(self, level, step, color_by) -> None:
        from geoshade.iso import IsoView

        old = self.view
        size = old.size if old is not None else self._size
        if old is not None:
            old.release()
            self.view = None
        self.view = IsoView(self.field, level, step=step, color_by=color_by, size=size,
                            ctx=self.ctx)

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, FieldSeries)

    @classmethod
    def demo(cls):
        from geoshade.compute.displacement import displacement_field

        field = displacement_field((64, 48, 48), steps=8, seed=0)
        return field, {"step": 5, "color_by": "PRESSURE"}

    @property
    def nsteps(self) -> int:
        return self.field.nsteps

    def level_range(self) -> tuple[float, float]:
        """The finite values of the shown step (the level slider's ends)."""
        info = self.view.info
        lo, hi = info.vmin, info.vmax
        if lo is None or hi is None or not np.isfinite([lo, hi]).all() or not lo < hi:
            return 0.0, 1.0
        return float(lo), float(hi)

    def color_names(self) -> list[str]:
        return list(self.field.properties)

    def settings(self) -> dict:
        v = self.view
        return {"level": v.level, "step": v.step, "color_by": v.color_by}

    def apply(self, **settings) -> list[Job]:
        extra = set(settings) - {"level", "step", "color_by"}
        if extra:
            raise unknown_settings(self, extra)
        v = self.view
        if "color_by" in settings and (settings["color_by"] or None) != v.color_by:
            # IsoView fixes color_by at construction: a new view on the same field
            self._make(settings.get("level", v.level), settings.get("step", v.step),
                       settings["color_by"] or None)
            return []
        if "step" in settings:
            v.set_step(int(settings["step"]))
        if "level" in settings:
            v.set_level(settings["level"])
        return []

    def readout(self, stats: dict) -> str:
        tri = stats.get("triangles")
        return (f"{stats.get('name') or 'field'} = {stats.get('level', 0):g} · step "
                f"{stats.get('step')} of {stats.get('nsteps')} ({stats.get('time')}) · "
                f"{'…' if tri is None else fmt_int(tri)} triangles")
