"""Options of the reservoir-grid View (checked before any GL context exists)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from geoshade.compute.grid.filters import Expression, Filter, Ranges, is_expression, shown_filter
from geoshade.errors import InputError
from geoshade.grid.geometry import display_bounds, parse_slice, plane_from_clip, world_centre
from geoshade.grid.lazy import check_options, is_lazy
from geoshade.io.grids.welltraj import read_wells
from geoshade.models.grid import CornerPointGrid, WellPath
from geoshade.models.names import derived_names, grid_property, step_names
from geoshade.models.steps import DEFAULT_STEP, resolve_step
from geoshade.scheduler import require_cluster
from geoshade.styles.checks import parse_bytes
from geoshade.styles.declare import option
from geoshade.styles.options import Plane, check_bool, check_choice, check_number, checks
from geoshade.styles.shared_options import (
    CULL,
    EXAGGERATION,
    PLANE,
    STEP,
    ClusterOptions,
    ColorOptions,
    ExaggerationOptions,
    MemoryOptions,
    ProgressiveOptions,
    SummaryOptions,
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

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
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


def read_well_files(path) -> list[WellPath]:
    """The well trajectories of a file (:func:`geoshade.io.grids.welltraj.read_wells`: geoshade
    text, RMS ASCII, CSV); one line for a missing file or one that holds none."""
    if not Path(path).exists():
        raise InputError(f"{path}: no such file (wells)")
    wells = read_wells(path)
    if isinstance(wells, WellPath):
        wells = [wells]
    if not isinstance(wells, list | tuple) or not all(isinstance(w, WellPath) for w in wells):
        raise InputError(f"{path}: not a well trajectory file (wells)")
    return list(wells)


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
class GridOptions(ExaggerationOptions, ColorOptions, ClusterOptions, ProgressiveOptions,
                  MemoryOptions, SummaryOptions):
    """Options of :class:`~geoshade.grid.GridView`.

    property: cell property to colour by (static or a report-step one; any case), or an
              expression over them with the filter's grammar (``"log10(PERMX)"``,
              ``"PORO * NTG"``); None: one colour
    step:     report step: index, -1 (last, the default), ``"R36"`` or a date (any part takes
              the same forms); resolved to an index, None for a grid without steps
    filter:   cell filter such as ``"PORO > 0.2 and PERMX > 100"`` (names in any case)
    ranges:   value ranges of properties (:class:`~geoshade.compute.grid.filters.Ranges`,
              ``"PORO=0.1:0.3,PERMX=100:"`` or ``{"PORO": (0.1, 0.3)}``): the cells with every
              value in its range are shown, with the filter (both hold)
    summary:  summary vectors of the case drawn against time with a cursor at the step (a
              strip under ``render``'s picture, a plot beside the viewers' 3D view)
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

    property: str | None = option(
        "auto", group="shown", metavar="NAME", control="property", example="PERMX",
        help="cell property to colour by, any case, or an expression with --filter's grammar "
             "such as 'log10(PERMX)' or 'PORO * NTG'; auto (the default): PORO where the grid "
             "has it, else its first property; none: one colour")
    exaggeration: Any = option("auto", **EXAGGERATION)
    step: Any = option(None, **STEP)
    diff: Any = option(
        None, group="shown", metavar="STEP", control="steps", example=0,
        help="draw the change since report step STEP (an index, R36 or a date, as --step): "
             "PROPERTY at --step minus PROPERTY at STEP on the active cells, on a diverging "
             "colour map centred on 0 (a symmetric colour range unless --color-range); the "
             "title names both steps")
    filter: Filter | None = option(
        None, group="cut", metavar="EXPR", example="PORO > 0.2",
        help="show only cells where EXPR holds, e.g. 'PORO > 0.2 and PERMX > 100' (names in "
             "any case)")
    ranges: Ranges | None = option(
        None, form="append", group="cut", metavar="NAME=LO:HI",
        control="ranges", example="PORO=0.1:0.3",
        help="show only cells with LO <= NAME <= HI (an end may be left out: PORO=0.2:), as "
             "well as --filter; repeat for several properties (the viewers' range sliders)")
    slice: Any = option(
        None, group="cut", metavar="i=A:B,j=C:D,k=E:F", example="k=1:5", control="ijk",
        help="IJK box, 0-based, B exclusive (numpy slices); 'k=3' is one layer")
    plane: Plane | None = option(None, **{**PLANE, "control": "section"})
    faults: str = option("show", choices=FAULT_MODES, group="shown", example="hide",
                         help="fault faces: as the others, highlighted, or hidden")
    approach: int = option(
        DEFAULT_APPROACH, choices=(1, 2, 3), type=int, group="method", example=2,
        help="1: packed nodes (conforming grids), 2: GS from COORD/ZCORN per cell, 3: faces "
             "from the CPU (default, least GPU memory)")
    zcorn_bits: int = option(16, choices=(16, 32), type=int, group="method", example=32,
                             help="ZCORN precision on the GPU (16: the paper's packing; error "
                                  "in the stats)")
    zcorn_store: str = option(
        DEFAULT_ZCORN_STORE, choices=("faces", "grid"), group="method", example="grid",
        help="approach 3: depths of the visible faces only (default) or the whole ZCORN "
             "indexed per face (the paper)")
    smear_faults: bool | None = option(
        None, form="switch", group="method", control="",
        help="approach 1 on a faulted grid: average the corners at each node without a warning "
             "(default: with a warning); --no-smear-faults refuses a faulted grid")
    edges: str = option("none", choices=EDGE_MODES, form="optional", const="quad",
                        group="shown", example="quad",
                        help="cell edges in the same pass (--edges alone = quad; paper = the "
                             "paper's per-triangle variant)")
    cull: bool = option(True, **CULL)
    wells: Any = option(
        None, form="append", group="wells", metavar="FILE", control="wells",
        help="well trajectories drawn as tubes (repeat for several files): a geoshade wells "
             "file ('WELL name' lines, each followed by 'x y z [md]' rows and 'MARKER x y z "
             "[label]' lines; # comments), an RMS ASCII well file (.rmswell/.w; a log named MD "
             "gives measured depths) or a CSV ('name, x, y, z[, md]', header optional); z is "
             "depth, down positive (default: the deck's wells)")
    deck_wells: bool = option(True, form="switch", group="wells", control="",
                              help="draw the deck's wells (WELSPECS/COMPDAT) where no --wells "
                                   "are given")
    wells_coords: str = option("grid", choices=("grid", "map"), group="wells", control="",
                               help="coordinates of the --wells files: grid (before MAPAXES) "
                                    "or map")
    well_radius: float | None = option(None, type=float, group="wells", metavar="M",
                                       example=40.0,
                                       help="tube radius in metres (default: 0.4 % of the "
                                            "grid's diagonal)")
    sim_wells: bool | None = option(
        None, form="switch", group="wells", example=False,
        help="the simulation wells of the restart file (IWEL/ICON/ZWEL of the shown step) as "
             "named pipes through their completion cells, producers green, water injectors "
             "blue, gas injectors red, shut ones grey (default: shown when the restart file "
             "has wells)")
    well_xray: bool = option(True, form="switch", group="wells", example=False,
                             help="draw the parts of wells hidden by cells as a half-tone on "
                                  "top")
    triad: str = option("enu", choices=("enu", "ijk"), group="picture", example="ijk",
                        help="the axes drawn in the corner: east/north/up (enu) or the grid's "
                             "I/J/K")
    medium: str | None = option(
        None, choices=("matrix", "fracture"), live=False, group="shown", control="",
        help="the medium of a dual-porosity or dual-permeability case (DUALPORO, DUALPERM) "
             "shown: matrix (the default) or fracture; the title says which")
    gpu_memory: int | None = option(
        None, live=False, group="cluster", metavar="SIZE", control="",
        help="GPU memory the picture may use (8G, 512M, bytes): a larger plan of the chosen "
             "approach stops before any GPU object, naming what it needs (`geoshade info CASE "
             "--gpu` lists every approach)")
    parts: Any = option(None, live=False, type=int, group="cluster", metavar="N", control="",
                        help="--distributed: cut the grid into N layer ranges (default two per "
                             "worker, whole k-slabs of the drawing order)")

    PART: ClassVar[str] = "grid"
    DEPRECATED: ClassVar[dict] = {"clip_plane": ("plane", _clip),
                                  "range": ("color_range", None)}

    def resolve(self, model, progress=None):
        """The data work, once: the automatic exaggeration and property, the deck's wells where
        none are given, whether the case's restart file has simulation wells (``sim_wells=
        None``: draw them where it has; ``True``: refused where it has none)."""

        if model is None or not isinstance(model, CornerPointGrid):
            return self
        out = self.resolve_exaggeration(display_bounds(model))
        if out.property == "auto":   # the one default property of every front end
            names = model.property_names()
            out = dataclasses.replace(out, property=(
                "PORO" if "PORO" in names else names[0] if names else None))
        deck = tuple(model.meta.get("wells") or ())
        if deck and self.deck_wells and self.wells is None:   # the one default of wells
            out = dataclasses.replace(out, wells=deck, wells_coords="grid")
        elif deck and not self.deck_wells and self.wells == deck:
            out = dataclasses.replace(out, wells=None)
        if out.summary:   # the vectors are the case's (one line naming the nearest ones)
            from geoshade.io.grids.summary import case_spec  # resfo

            case_spec(model).match(out.summary)
        if self.sim_wells is None or self.sim_wells is True:
            has = _has_sim_wells(model)
            if self.sim_wells is None:
                return dataclasses.replace(out, sim_wells=has)
            if not has:
                raise _no_sim_wells(model)
        return out

    @staticmethod
    @checks("property")
    def check_property(value, model):
        if isinstance(value, str) and value.strip().lower() in ("auto", "none"):
            return None if value.strip().lower() == "none" else "auto"
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
    @checks("diff")
    def check_diff(value, model):
        """The report step a difference is taken from, resolved as ``step`` is (None: none)."""
        if value is None or model is None:
            return value
        if not model.steps:
            raise InputError(f"diff: {model.name or 'the grid'} has no report steps (no "
                             "UNRST): a difference needs two")
        return resolve_step(value, len(model.steps), dates=model.step_dates,
                            reports=model.meta.get("unrst_seqnum") or (), where=model.name)

    @staticmethod
    @checks("filter")
    def check_filter(value, model):
        f = Filter.parse(value)
        if f is not None and model is not None:

            f.resolve([*model.property_names(), *derived_names(model)])
        return f

    @staticmethod
    @checks("ranges")
    def check_ranges(value, model):
        r = Ranges.parse(value)
        if r is not None and model is not None:
            available = [*model.property_names(), *derived_names(model)]
            try:
                Filter(r.expr).resolve(available)
            except InputError as err:   # an unknown name: one line naming the available ones
                raise InputError(f"range {r.text()}: {str(err).split(': ', 1)[1]}") from None
        return r

    def cells_filter(self) -> Filter | None:
        """The cells shown: the typed ``filter`` and the ``ranges`` (both hold)."""
        return shown_filter(self.filter, self.ranges)

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
        """WellPath objects, or files of trajectories (read here: :func:`read_well_files`);
        None: the default (the deck's wells, see ``deck_wells``); False or empty: no wells."""
        if value is None:
            return None
        if value is False or (isinstance(value, list | tuple) and not value):
            return ()
        items = [value] if isinstance(value, WellPath | str | Path) else list(value)
        wells: list[WellPath] = []
        for w in items:
            if isinstance(w, str | Path):
                wells += read_well_files(w)
            elif isinstance(w, WellPath):
                wells.append(w)
            else:
                raise InputError(f"wells: expected WellPath objects or trajectory files, got "
                                 f"{type(w).__name__}")
        return tuple(wells)

    @staticmethod
    @checks("sim_wells")
    def check_sim_wells(value, model=None):
        """True/False, or None (decided by :meth:`GridOptions.resolve`, which reads the
        restart file's well index)."""
        return None if value is None else check_bool(value, "sim_wells")

    @staticmethod
    @checks("well_radius")
    def check_well_radius(value, model=None):
        return check_number(value, "well_radius (metres)", positive=True, allow_none=True)

    @staticmethod
    @checks("parts")
    def check_parts(value, model=None):
        return None if value is None else check_number(value, "parts", lo=1, integer=True)

    def validate(self, model) -> None:
        super().validate(model)
        if self.diff is not None and model is not None and isinstance(model, CornerPointGrid):
            self._check_diff(model)

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

    def _check_diff(self, model) -> None:
        name = self.property
        if name in (None, "auto"):
            raise InputError("diff: a difference is of a property; give --property (e.g. "
                             "SWAT)")
        dynamic = [*step_names(model), *derived_names(model)]
        moves = name in dynamic or (is_expression(name) and Expression.parse(name).uses(dynamic))
        if not moves:
            raise InputError(f"diff: {name} does not change with the report step (a static "
                             f"property); a difference needs one that does, such as "
                             f"{', '.join(dynamic[:4]) or 'SWAT'}")

    @staticmethod
    @checks("gpu_memory")
    def check_gpu_memory(value, model=None):

        return None if value is None else parse_bytes(value)


__all__ = ["DEFAULT_APPROACH", "DEFAULT_ZCORN_STORE", "EDGE_MODES", "FAULT_MODES", "GridOptions",
           "read_well_files", "resolve_property", "step_names"]
