"""Options of the reservoir-grid View (checked before any GL context exists)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

from geoshade.compute.grid_filter import Expression, Filter, is_expression
from geoshade.errors import InputError
from geoshade.grid.geometry import parse_slice, plane_from_clip, world_centre
from geoshade.models.grid import CornerPointGrid, WellPath
from geoshade.models.names import grid_property, step_names
from geoshade.models.steps import resolve_step
from geoshade.styles.options import (
    ColorStyle,
    Plane,
    ViewOptions,
    check_bool,
    check_choice,
    check_exaggeration,
    check_number,
)

#: the approach ``render`` uses unless told: approach 3 with the faces storage is the one that
#: draws any grid (faults included) with the least GPU memory (``geoshade bench grid``)
DEFAULT_APPROACH = 3
DEFAULT_ZCORN_STORE = "faces"
FAULT_MODES = ("show", "highlight", "hide")
EDGE_MODES = ("none", "quad", "paper")


def resolve_property(grid: CornerPointGrid | None, name) -> str | None:
    """The grid's own spelling of property ``name`` (matched case-insensitively), or an
    expression over its properties (``"log10(PERMX)"``: the grammar of a filter), checked.

    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> resolve_property(synthetic_grid(3, 3, 2), "poro")
    'PORO'
    >>> resolve_property(synthetic_grid(3, 3, 2), " log10( permx ) ")
    'log10( permx )'
    """
    if is_expression(name):
        e = Expression.parse(name)
        if grid is not None:
            from geoshade.models.names import derived_names

            e.resolve([*grid.property_names(), *derived_names(grid)])
        return e.expr
    return grid_property(grid, name) if grid is not None else name


def _clip(value, grid):
    return plane_from_clip(value, grid)


@dataclass(frozen=True)
class GridOptions(ViewOptions):
    """Options of :class:`~geoshade.grid.GridView`.

    property: cell property to colour by (static or a report-step one; any case), or an
              expression over them with the filter's grammar (``"log10(PERMX)"``,
              ``"PORO * NTG"``); None: one colour
    step:     report step: index, -1 (last, the default), ``"R36"`` or a date (any part takes
              the same forms); resolved to an index, None for a grid without steps
    filter:   cell filter such as ``"PORO > 0.2 and PERMX > 100"`` (names in any case)
    slice:    IJK box ``"i=A:B,j=C:D,k=E"`` (0-based, B exclusive) or a dict
    plane:    :class:`Plane` cutting the grid (cells whose centre is on the kept side stay); the
              old ``clip_plane`` (relative to the grid's centre, depth down) still works
    faults:   ``show highlight hide``
    exaggeration: vertical exaggeration
    approach: the paper's approach 1, 2 or 3; ``zcorn_bits`` 16/32; ``zcorn_store``
              ``faces``/``grid``; ``smear_faults`` (approach 1 on a faulted grid: None smears the
              faults with a warning, True smears quietly, False refuses the grid)
    edges:    ``none quad paper`` (True = quad)
    cull:     skip back faces
    color:    :class:`ColorStyle` (shorthands ``colormap``, ``color_range``, ``log`` ...)
    wells:    WellPath list drawn as tubes; ``wells_coords`` ``grid``/``map``; ``well_radius``
    sim_wells: the simulation wells of the case's restart file (IWEL/ICON/ZWEL of the shown
              report step) as pipes from a head above the grid through their completion cells,
              named, coloured by type (shut: grey); None (default): shown when the restart
              file has wells
    well_xray: the parts of wells hidden behind cells are drawn on top as a lighter half-tone
              (default True), so wells stay visible in an opaque grid
    triad:    the annotation's axes: ``enu`` (east, north, up) or ``ijk`` (the grid's I, J, K)
    gpu_memory: bytes (or ``"8G"``) the GPU may hold: a larger plan of the chosen approach is
              refused before any GPU object is made (:mod:`geoshade.grid.plan`)
    scheduler: where a grid out of core (a grid store) computes its faces chunk by chunk:
              None (dask threads), ``"local:N"``, a scheduler address or a Client
    """

    property: str | None = None
    step: Any = None
    filter: Filter | None = None
    slice: Any = None
    plane: Plane | None = None
    faults: str = "show"
    exaggeration: float = 1.0
    approach: int = DEFAULT_APPROACH
    zcorn_bits: int = 16
    zcorn_store: str = DEFAULT_ZCORN_STORE
    smear_faults: bool | None = None
    edges: str = "none"
    cull: bool = True
    color: ColorStyle = field(default_factory=ColorStyle)
    wells: Any = None
    wells_coords: str = "grid"
    well_radius: float | None = None
    sim_wells: bool | None = None
    well_xray: bool = True
    triad: str = "enu"
    gpu_memory: int | None = None
    scheduler: Any = None

    PART: ClassVar[str] = "grid"
    DEPRECATED: ClassVar[dict] = {"clip_plane": ("plane", _clip)}

    @staticmethod
    def check_property(value, model):
        return resolve_property(model, value)

    @staticmethod
    def check_step(value, model):
        if model is None:
            return value
        n = len(model.steps)
        if n == 0:
            if value is None:
                return None
            raise InputError(f"step: {model.name or 'the grid'} has no report steps (no UNRST); "
                             f"step {value} does not exist")
        return resolve_step(value, n, dates=model.step_dates,
                            reports=model.meta.get("unrst_seqnum") or (), where=model.name)

    @staticmethod
    def check_filter(value, model):
        f = Filter.parse(value)
        if f is not None and model is not None:
            from geoshade.models.names import derived_names

            f.resolve([*model.property_names(), *derived_names(model)])
        return f

    @staticmethod
    def check_slice(value, model):
        return parse_slice(value, model.dims) if model is not None else value

    @staticmethod
    def check_plane(value, model):
        p = Plane.parse(value)
        if p is not None and model is not None:
            p = p.resolve(world_centre(model))
        return p

    @staticmethod
    def check_faults(value, model=None):
        return check_choice(value, FAULT_MODES, "faults")

    @staticmethod
    def check_exaggeration(value, model=None):
        return check_exaggeration(value)

    @staticmethod
    def check_approach(value, model=None):
        return check_number(value, "approach", 1, 3, integer=True)

    @staticmethod
    def check_zcorn_bits(value, model=None):
        if value not in (16, 32):
            raise InputError(f"zcorn_bits: expected 16 or 32, got {value!r}")
        return int(value)

    @staticmethod
    def check_zcorn_store(value, model=None):
        return check_choice(value, ("faces", "grid"), "zcorn_store")

    @staticmethod
    def check_smear_faults(value, model=None):
        return None if value is None else check_bool(value, "smear_faults")

    @staticmethod
    def check_edges(value, model=None):
        mode = {False: "none", None: "none", True: "quad"}.get(value, value) \
            if isinstance(value, bool | None) else value
        return check_choice(mode, EDGE_MODES, "edges")

    @staticmethod
    def check_wells(value, model=None):
        if not value:
            return None
        wells = [value] if isinstance(value, WellPath) else list(value)
        for w in wells:
            if not isinstance(w, WellPath):
                raise InputError(f"wells: expected WellPath objects, got {type(w).__name__}")
        return tuple(wells)

    @staticmethod
    def check_sim_wells(value, model=None):
        if value is not None:
            value = check_bool(value, "sim_wells")
        if model is None:
            return value
        from geoshade.io.grids.restart_wells import has_restart_wells, restart_wells

        has = bool(model.steps) and has_restart_wells(model)
        if value is None:
            return has
        if value and not has:
            index = restart_wells(model)
            why = ("it has no restart file (UNRST) beside its EGRID" if index is None else
                   f"its restart file {index.path.name} has no well records (IWEL)")
            raise InputError(f"sim_wells: {model.name or 'the grid'} has no simulation wells: "
                             f"{why}")
        return value

    @staticmethod
    def check_triad(value, model=None):
        return check_choice(value, ("enu", "ijk"), "triad")

    @staticmethod
    def check_wells_coords(value, model=None):
        return check_choice(value, ("grid", "map"), "wells_coords")

    @staticmethod
    def check_well_radius(value, model=None):
        return check_number(value, "well_radius (metres)", positive=True, allow_none=True)

    @staticmethod
    def check_gpu_memory(value, model=None):
        from geoshade.grid.plan import parse_bytes

        return None if value is None else parse_bytes(value)


__all__ = ["DEFAULT_APPROACH", "DEFAULT_ZCORN_STORE", "EDGE_MODES", "FAULT_MODES", "GridOptions",
           "resolve_property", "step_names"]
