"""Options of the reservoir-grid View (checked before any GL context exists)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, ClassVar

from geoshade.compute.grid_filter import Expression, Filter, is_expression
from geoshade.errors import InputError
from geoshade.grid.geometry import parse_slice, plane_from_clip, world_centre
from geoshade.grid.lazy import check_options, is_lazy
from geoshade.grid.plan import parse_bytes
from geoshade.models.grid import CornerPointGrid, WellPath
from geoshade.models.names import derived_names, grid_property, step_names
from geoshade.models.steps import DEFAULT_STEP, resolve_step
from geoshade.scheduler import Scheduler, require_cluster
from geoshade.styles.options import (
    ColorStyle,
    Plane,
    ViewOptions,
    check_bool,
    check_choice,
    check_exaggeration,
    check_number,
    checks,
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

            e.resolve([*grid.property_names(), *derived_names(grid)])
        return e.expr
    return grid_property(grid, name) if grid is not None else name


def _clip(value, grid):
    return plane_from_clip(value, grid)


def _has_sim_wells(model) -> bool:
    """Whether ``model``'s restart file has well records; one line where there is none."""
    from geoshade.io.grids.restart_wells import has_restart_wells

    return bool(model.steps) and has_restart_wells(model)


def _no_sim_wells(model) -> InputError:
    from geoshade.io.grids.restart_wells import restart_wells

    index = restart_wells(model)
    why = ("it has no restart file (UNRST) beside its EGRID" if index is None else
           f"its restart file {index.path.name} has no well records (IWEL)")
    return InputError(f"sim_wells: {model.name or 'the grid'} has no simulation wells: {why}")


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
    scheduler: where the View's dask work runs (:class:`~geoshade.scheduler.Scheduler`): a
              grid store's faces chunk by chunk, and the cluster drawn on with ``distributed``;
              None (dask threads), ``"local:N"``, a scheduler address or a Client
    distributed: draw on the ``scheduler``'s cluster (the same option for the core): each
              worker computes and draws the faces of its layer ranges, composited by depth
              (:class:`~geoshade.grid.distributed.ClusterFaces`); approach 3 with faces, no
              cutting plane. ``parts``: the number of layer ranges (default two per worker);
              ``worker_timeout``: seconds a worker may take for one call (300)
    progressive: a picture at once: draw the coarse level of detail first (a grid store's
              stored level, or merged in memory; :mod:`geoshade.render.progressive`), then
              the full grid
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
    distributed: bool = False
    parts: Any = None
    worker_timeout: float = 300.0
    progressive: bool = False

    PART: ClassVar[str] = "grid"
    DEPRECATED: ClassVar[dict] = {"clip_plane": ("plane", _clip)}
    CHOICES: ClassVar[dict[str, tuple]] = {
        **ViewOptions.CHOICES, "faults": FAULT_MODES, "edges": EDGE_MODES,
        "approach": (1, 2, 3), "zcorn_bits": (16, 32), "zcorn_store": ("faces", "grid"),
        "wells_coords": ("grid", "map"), "triad": ("enu", "ijk")}
    FLAGS: ClassVar[tuple[str, ...]] = (*ViewOptions.FLAGS, "cull", "well_xray", "distributed",
                                        "progressive")

    def resolve(self, model, progress=None):
        """The data work, once: whether the case's restart file has simulation wells
        (``sim_wells=None``: draw them where it has; ``True``: refused where it has none)."""

        if model is None or not isinstance(model, CornerPointGrid):
            return self
        if self.sim_wells is None or self.sim_wells is True:
            has = _has_sim_wells(model)
            if self.sim_wells is None:
                return dataclasses.replace(self, sim_wells=has)
            if not has:
                raise _no_sim_wells(model)
        return self

    @staticmethod
    @checks("property")
    def check_property(value, model):
        return resolve_property(model, value)

    @staticmethod
    @checks("step")
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
                            reports=model.meta.get("unrst_seqnum") or (), where=model.name,
                            default=model.meta.get("default_step", DEFAULT_STEP))

    @staticmethod
    @checks("filter")
    def check_filter(value, model):
        f = Filter.parse(value)
        if f is not None and model is not None:

            f.resolve([*model.property_names(), *derived_names(model)])
        return f

    @staticmethod
    @checks("slice")
    def check_slice(value, model):
        return parse_slice(value, model.dims) if model is not None else value

    @staticmethod
    @checks("plane")
    def check_plane(value, model):
        p = Plane.parse(value)
        if p is not None and model is not None:
            p = p.resolve(world_centre(model))
        return p

    @staticmethod
    @checks("faults")
    def check_faults(value, model=None):
        return check_choice(value, FAULT_MODES, "faults")

    @staticmethod
    @checks("exaggeration")
    def check_exaggeration(value, model=None):
        return check_exaggeration(value)

    @staticmethod
    @checks("approach")
    def check_approach(value, model=None):
        return check_number(value, "approach", 1, 3, integer=True)

    @staticmethod
    @checks("zcorn_bits")
    def check_zcorn_bits(value, model=None):
        if value not in GridOptions.CHOICES["zcorn_bits"]:
            raise InputError(f"zcorn_bits: expected 16 or 32, got {value!r}")
        return int(value)

    @staticmethod
    @checks("zcorn_store")
    def check_zcorn_store(value, model=None):
        return check_choice(value, GridOptions.CHOICES["zcorn_store"], "zcorn_store")

    @staticmethod
    @checks("smear_faults")
    def check_smear_faults(value, model=None):
        return None if value is None else check_bool(value, "smear_faults")

    @staticmethod
    @checks("edges")
    def check_edges(value, model=None):
        mode = {False: "none", None: "none", True: "quad"}.get(value, value) \
            if isinstance(value, bool | None) else value
        return check_choice(mode, EDGE_MODES, "edges")

    @staticmethod
    @checks("wells")
    def check_wells(value, model=None):
        if not value:
            return None
        wells = [value] if isinstance(value, WellPath) else list(value)
        for w in wells:
            if not isinstance(w, WellPath):
                raise InputError(f"wells: expected WellPath objects, got {type(w).__name__}")
        return tuple(wells)

    @staticmethod
    @checks("sim_wells")
    def check_sim_wells(value, model=None):
        """True/False, or None (decided by :meth:`GridOptions.resolve`, which reads the
        restart file's well index)."""
        return None if value is None else check_bool(value, "sim_wells")

    @staticmethod
    @checks("triad")
    def check_triad(value, model=None):
        return check_choice(value, GridOptions.CHOICES["triad"], "triad")

    @staticmethod
    @checks("wells_coords")
    def check_wells_coords(value, model=None):
        return check_choice(value, GridOptions.CHOICES["wells_coords"], "wells_coords")

    @staticmethod
    @checks("well_radius")
    def check_well_radius(value, model=None):
        return check_number(value, "well_radius (metres)", positive=True, allow_none=True)

    @staticmethod
    @checks("scheduler")
    def check_scheduler(value, model=None):
        return None if value is None else Scheduler.parse(value)

    @staticmethod
    @checks("parts")
    def check_parts(value, model=None):
        return None if value is None else check_number(value, "parts", lo=1, integer=True)

    @staticmethod
    @checks("worker_timeout")
    def check_worker_timeout(value, model=None):
        return check_number(value, "worker_timeout (seconds)", positive=True)

    def validate(self, model) -> None:
        super().validate(model)
        if model is not None and is_lazy(model):   # a grid store: before any work or GL
            check_options(model, self)
        if not self.distributed:
            return
        require_cluster(self.scheduler, True, "GridView")
        name = getattr(model, "name", "") or "grid"
        if self.approach != 3 or self.zcorn_store != "faces":
            raise InputError(f"{name}: a grid drawn on a cluster is drawn with approach 3 and "
                             "zcorn_store='faces' (each worker holds its faces' corners)")
        if self.plane is not None:
            raise InputError(f"{name}: a cutting plane needs every cell centre on one "
                             "machine; on a cluster use an IJK slice or a filter")

    @staticmethod
    @checks("gpu_memory")
    def check_gpu_memory(value, model=None):

        return None if value is None else parse_bytes(value)


__all__ = ["DEFAULT_APPROACH", "DEFAULT_ZCORN_STORE", "EDGE_MODES", "FAULT_MODES", "GridOptions",
           "resolve_property", "step_names"]
