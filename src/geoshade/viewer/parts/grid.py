"""Reservoir-grid part adapter: property, report step, cell filter, IJK slices, edges, faults,
wells, vertical exaggeration (all forwarded to :class:`geoshade.grid.GridView`)."""

from __future__ import annotations

import numpy as np

from geoshade.errors import InputError
from geoshade.models.grid import CornerPointGrid, WellPath
from geoshade.viewer.parts.base import Job, Part, auto_exaggeration, fmt_int, unknown_settings

_SETTINGS = ("property", "step", "filter", "slice", "edges", "faults", "wells")


def demo_wells(grid: CornerPointGrid) -> list[WellPath]:
    """Two deviated wells through the grid, in grid coordinates, for the demo.

    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> [w.name for w in demo_wells(synthetic_grid(8, 6, 4))]
    ['INJ', 'PROD']
    """
    b = grid.bounds()
    (x0, y0, z0), (x1, y1, z1) = b
    t = np.linspace(0.0, 1.0, 12)[:, None]
    top, bot = z0 - 0.1 * (z1 - z0), z1

    def path(ax, ay, bx, by):
        xy = np.array([ax, ay]) + t * np.array([bx - ax, by - ay]) * t
        return np.column_stack([x0 + xy[:, 0] * (x1 - x0), y0 + xy[:, 1] * (y1 - y0),
                                top + t[:, 0] * (bot - top)])

    inj, prod = path(0.12, 0.12, 0.2, 0.25), path(0.8, 0.75, 0.7, 0.6)
    return [WellPath("INJ", inj, markers=inj[-3:-1]), WellPath("PROD", prod, markers=prod[-3:-1])]


class GridPart(Part):
    """The corner-point grid view.

    Settings: ``property`` (name or None), ``step`` (report step or None), ``filter``
    (expression or ""), ``slice`` ({"i": (a, b), "j": ..., "k": ...}, 0-based, b exclusive, or
    the string form ``"i=A:B,k=C"``), ``edges`` (bool or 'quad'/'paper'), ``faults``
    ('show'/'highlight'/'hide'), ``wells`` (bool: the deck's wells on or off).
    """

    kind = "grid"
    title = "reservoir grid"
    exaggeration = True

    def __init__(self, grid: CornerPointGrid, size=(800, 600), property=None, step=None,
                 filter=None, slice=None, edges=False, faults: str = "show", wells=True,
                 exaggeration: float | None = None, ctx=None):
        from geoshade.grid import GridView
        from geoshade.grid.api import display_bounds

        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"grid: expected a CornerPointGrid, got {type(grid).__name__}")
        self.grid = grid
        self.wells = list((grid.meta or {}).get("wells") or [])
        if property is None and grid.property_names():
            names = grid.property_names()
            property = "PORO" if "PORO" in names else names[0]
        if exaggeration is None:  # flat reservoirs: a round factor that shows the layers
            exaggeration = auto_exaggeration(display_bounds(grid))
        self.view = GridView(grid, property=property, step=step, filter=filter, slice=slice,
                             edges=edges, faults=faults, exaggeration=exaggeration, size=size,
                             ctx=ctx)
        self.wells_on = False
        self._pending_faces: dict = {}
        self._set_wells(bool(wells))

    @classmethod
    def accepts(cls, model) -> bool:
        return isinstance(model, CornerPointGrid)

    @classmethod
    def demo(cls):
        from geoshade.compute.synthetic_grid import synthetic_grid

        grid = synthetic_grid(24, 18, 8, seed=3)
        grid.meta["wells"] = demo_wells(grid)
        return grid, {"edges": True, "exaggeration": 5.0}

    def _set_wells(self, on: bool) -> None:
        self.wells_on = bool(on) and bool(self.wells)
        self.view.set_wells(self.wells if self.wells_on else None)

    def steps(self) -> int:
        return len(self.grid.steps)

    def slice_dict(self) -> dict:
        return {ax: (s.start, s.stop) for ax, s in zip("ijk", self.view.state.slice, strict=True)}

    def settings(self) -> dict:
        st = self.view.state
        return {"property": st.property, "step": st.step, "filter": st.filter or "",
                "slice": self.slice_dict(), "edges": self.view.edge_style.mode,
                "faults": st.faults, "wells": self.wells_on}

    def apply(self, **settings) -> list[Job]:
        extra = set(settings) - set(_SETTINGS) - {"exaggeration"}
        if extra:
            raise unknown_settings(self, extra)
        v = self.view
        if "property" in settings or "step" in settings:
            prop = settings.get("property", v.state.property)
            step = settings.get("step", v.state.step if prop == v.state.property else None)
            v.set_property(prop or None, step=step)
        if "edges" in settings:
            v.set_edges(settings["edges"])
        if "wells" in settings:
            self._set_wells(settings["wells"])
        if "exaggeration" in settings:
            self.set_exaggeration(settings["exaggeration"])
        faces = {k: settings[k] for k in ("filter", "slice", "faults") if k in settings}
        return [self.faces_job(faces)] if faces else []

    def faces_job(self, changes: dict) -> Job:
        """New visible faces for a filter/slice/faults change: built on a worker thread
        (a 1e8-cell grid takes seconds), uploaded on the GL thread. Changes not yet applied
        are carried into the next job, so a superseded job loses nothing."""
        from geoshade.grid.api import FAULT_MODES, parse_slice

        v = self.view
        if "faults" in changes and changes["faults"] not in FAULT_MODES:
            raise InputError(f"faults: expected one of {', '.join(FAULT_MODES)}, "
                             f"got {changes['faults']!r}")
        if "slice" in changes:
            changes["slice"] = parse_slice(changes["slice"], v.grid.dims)
        if "filter" in changes:
            changes["filter"] = changes["filter"] or None
        self._pending_faces.update(changes)
        pending = dict(self._pending_faces)

        def apply(prepared) -> None:
            v.apply_faces(prepared)
            for k, val in prepared.changes.items():
                if self._pending_faces.get(k, None) is val:
                    del self._pending_faces[k]

        return Job("grid-faces", "visible faces",
                   lambda progress: v.prepare_faces(**pending), apply)

    def readout(self, stats: dict) -> str:
        prop = stats.get("property") or "no property"
        step = "" if stats.get("step") is None else f" step {stats['step']}"
        drawn = stats.get("faces_drawn")
        wells = f" · {stats['wells']} wells" if stats.get("wells") else ""
        return (f"{prop}{step} · {fmt_int(stats.get('shown_cells'))} of "
                f"{fmt_int(stats.get('active_cells'))} cells · "
                f"{'…' if drawn is None else fmt_int(drawn)} faces{wells}")
