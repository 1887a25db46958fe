"""Geometry of the reservoir-grid view: IJK slices, bounds and matrices (no GL).

Coordinates: the grid's own (x, y, depth) go to the GPU relative to a local origin; the model
matrix applies MAPAXES (grid -> map x, y) and shows depth upwards-negative, scaled by the
vertical exaggeration (world z = -exaggeration * depth: shallow cells on top). Planes and camera
framing use the world without exaggeration's effect on meaning: x east, y north, z up.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from geoshade.compute.grid import kernels as grid_kernels
from geoshade.errors import InputError
from geoshade.grid.lazy import bounds
from geoshade.models.grid import MAX_COORDINATE, CornerPointGrid, WellPath
from geoshade.styles.options import Plane

_AXES = "ijk"


def parse_slice(spec, dims) -> tuple[slice, slice, slice]:
    """IJK box from ``"i=A:B,j=C:D,k=E"`` (0-based, B exclusive, as numpy) or a dict.

    >>> parse_slice("i=1:3,k=4", (5, 6, 7))
    (slice(1, 3, None), slice(0, 6, None), slice(4, 5, None))
    >>> parse_slice({"j": (2, None)}, (5, 6, 7))[1]
    slice(2, 6, None)
    """
    out = {ax: (0, n) for ax, n in zip(_AXES, dims, strict=True)}
    if spec is None or spec == "":
        return tuple(slice(*out[ax]) for ax in _AXES)
    if isinstance(spec, tuple | list) and len(spec) == 3 and all(isinstance(v, slice)
                                                               for v in spec):
        spec = dict(zip(_AXES, spec, strict=True))
    expect = ("slice: expected i=A:B,j=A:B,k=A:B with 0-based cell indices (B exclusive, "
              "either side may be left out, a single number is one layer)")
    if isinstance(spec, str):
        items = {}
        for part in spec.split(","):
            m = re.fullmatch(r"\s*([ijkIJK])\s*=\s*(\d*)\s*(?::\s*(\d*))?\s*", part)
            if not m:
                raise InputError(f"{expect}; got {spec!r}")
            ax, a, b = m.group(1).lower(), m.group(2), m.group(3)
            if ax in items:
                raise InputError(f"slice: axis {ax} given twice in {spec!r}")
            if b is None:  # a single layer
                if a == "":
                    raise InputError(f"{expect}; got {spec!r}")
                items[ax] = (int(a), int(a) + 1)
            else:
                items[ax] = (int(a) if a else None, int(b) if b else None)
    elif isinstance(spec, dict):
        items = {}
        for ax, v in spec.items():
            if str(ax).lower() not in _AXES:
                raise InputError(f"slice: unknown axis {ax!r}; expected i, j or k")
            if isinstance(v, slice):
                v = (v.start, v.stop)
            elif np.isscalar(v):
                v = (int(v), int(v) + 1)
            items[str(ax).lower()] = tuple(v)
    else:
        raise InputError(f"{expect}; got {spec!r}")
    for ax, (a, b) in items.items():
        n = dims[_AXES.index(ax)]
        a = 0 if a is None else int(a)
        b = n if b is None else int(b)
        if not 0 <= a < b <= n:
            raise InputError(f"slice: {ax}={a}:{b} is empty or outside 0:{n} (the grid has "
                             f"{n} cells along {ax})")
        out[ax] = (a, b)
    return tuple(slice(*out[ax]) for ax in _AXES)


def plane_from_clip(clip, grid: CornerPointGrid | None):
    """The :class:`~geoshade.styles.options.Plane` of the deprecated ``clip_plane``/``--clip``.

    ``clip`` is ``NX,NY,NZ,D`` in the old meaning: cells kept where ``n̂·(c - centre) + D >= 0``
    with ``c`` and ``centre`` in map x, y and *depth* (positive down) and ``centre`` the grid's
    centre. The same cells are kept by the new plane (z up), so old commands draw the same.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 4, 2)
    >>> p = plane_from_clip("0,0,1,0", g)          # old: keep the deeper half
    >>> p.normal
    (0.0, 0.0, -1.0)
    """

    try:
        vals = ([float(v) for v in clip.split(",")] if isinstance(clip, str)
                else [float(v) for v in clip])
    except (TypeError, ValueError):
        raise InputError(f"clip: expected NX,NY,NZ,D (four numbers), got {clip!r}") from None
    if len(vals) != 4 or not np.all(np.isfinite(vals)) or not any(vals[:3]):
        raise InputError(f"clip: expected NX,NY,NZ,D with a non-zero normal, got {clip!r}")
    n = np.array([vals[0], vals[1], -vals[2]])
    n = n / np.linalg.norm(n)
    if grid is None:  # only the syntax is checked (no grid read yet)
        return Plane(tuple(float(v) for v in n), 0.0)  # type: ignore[arg-type]
    centre = world_centre(grid)
    return Plane(tuple(float(v) for v in n), float(n @ centre - vals[3]))  # type: ignore[arg-type]


def world_centre(grid: CornerPointGrid) -> np.ndarray:
    """(3,) centre of the grid's display bounds in map x, y and z up (= -depth), unexaggerated."""
    c = display_bounds(grid).mean(axis=0)
    t = grid.map_transform()
    xy = c[:2] @ t[:2, :2].T + t[:2, 2]
    return np.array([xy[0], xy[1], -c[2]])


def display_bounds(grid: CornerPointGrid) -> np.ndarray:
    """(2, 3) grid-coordinate bounds (x, y, depth) of the pillars and the active cells' depths.

    One pass over ZCORN (numba from :data:`geoshade.compute.grid.kernels.MIN_CELLS` cells on;
    ~1 s at 1e8 cells), remembered on the grid for the arrays it was computed from: framing,
    every draw and the origin ask again without a second pass.  Replacing ``zcorn``, ``coord``
    or ``actnum`` by other arrays computes it anew (arrays changed in place are not seen).
    """

    return _bounds(grid)[1].copy()


def plane_box(grid: CornerPointGrid) -> np.ndarray:
    """(2, 3) box of the active cells in the coordinates of a cutting plane: map x, y (MAPAXES
    applied) and z up (minus the depth).

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> plane_box(synthetic_grid(4, 3, 2))[:, 2] <= 0
    array([ True,  True])
    """
    b = display_bounds(grid)
    t = grid.map_transform()
    xy = np.array([[b[i, 0], b[j, 1], 1.0] for i in (0, 1) for j in (0, 1)]) @ t.T
    return np.array([[*xy[:, :2].min(0), -b[1, 2]], [*xy[:, :2].max(0), -b[0, 2]]])


def grid_bounds(grid: CornerPointGrid) -> np.ndarray:
    """(2, 3) :meth:`CornerPointGrid.bounds` (every usable corner, inactive cells too),
    remembered with :func:`display_bounds`."""
    return _bounds(grid)[0].copy()


def _bounds(grid: CornerPointGrid) -> tuple[np.ndarray, np.ndarray]:

    key = (id(grid.zcorn), id(grid.coord), id(grid.actnum), grid.dims)
    cached = grid.__dict__.get("_display_bounds")
    if cached is not None and cached[0] == key:
        return cached[1]
    if not isinstance(grid.zcorn, np.ndarray):  # a grid out of core: one dask pass

        full, b = bounds(grid)
        grid.__dict__["_display_bounds"] = (key, (full, b))
        return full, b
    full = grid.bounds()
    b = full.copy()
    if grid_kernels.use_kernels(grid.ncells) and isinstance(grid.zcorn, np.ndarray):
        depths = grid_kernels.active_depth_range(grid.zcorn, grid.active, MAX_COORDINATE)
    else:
        depths = grid.active_depth_range()   # in slabs: no copy of ZCORN
    if depths is not None:
        b[0, 2], b[1, 2] = depths
    grid.__dict__["_display_bounds"] = (key, (full, b))
    return full, b


def model_matrix(grid: CornerPointGrid, origin, exaggeration: float = 1.0) -> np.ndarray:
    """4×4 matrix from local GPU coordinates (x, y, depth minus ``origin``) to the world.

    World x, y are map coordinates (MAPAXES applied); world z = -exaggeration * depth.
    """
    t = grid.map_transform()
    o = np.asarray(origin, float)
    m = np.eye(4)
    m[:2, :2] = t[:2, :2]
    m[:2, 3] = t[:2, :2] @ o[:2] + t[:2, 2]
    m[2, 2] = -float(exaggeration)
    m[2, 3] = -float(exaggeration) * o[2]
    return m


def world_points(grid: CornerPointGrid, pts, exaggeration: float, coords: str = "grid"
                 ) -> np.ndarray:
    """(n, 3) grid (or map) x, y, depth -> world x, y, z (float64)."""
    p = np.asarray(pts, float).reshape(-1, 3)
    out = np.empty_like(p)
    if coords == "grid":
        t = grid.map_transform()
        out[:, :2] = p[:, :2] @ t[:2, :2].T + t[:2, 2]
    elif coords == "map":
        out[:, :2] = p[:, :2]
    else:
        raise InputError(f"wells_coords: expected 'grid' or 'map', got {coords!r}")
    out[:, 2] = -float(exaggeration) * p[:, 2]
    return out


def world_bounds(grid: CornerPointGrid, exaggeration: float = 1.0) -> np.ndarray:
    b = display_bounds(grid)
    corners = np.array([[b[i, 0], b[j, 1], b[k, 2]] for i in (0, 1) for j in (0, 1)
                        for k in (0, 1)])
    w = world_points(grid, corners, exaggeration)
    return np.array([w.min(0), w.max(0)])


def frame_points(grid: CornerPointGrid, exaggeration: float = 1.0) -> np.ndarray:
    """(8, 3) world points the view must show: the grid's four corner pillars at the top and
    bottom depths of its active cells."""
    nx, ny, _ = grid.dims
    b = display_bounds(grid)
    c = np.asarray(grid.coord, float)[[0, nx, 0, nx], [0, 0, ny, ny]]  # (4, 6)
    pts = []
    for z in (b[0, 2], b[1, 2]):
        dz = c[:, 5] - c[:, 2]
        t = np.where(dz != 0, (z - c[:, 2]) / np.where(dz != 0, dz, 1.0), 0.0)
        pts.append(np.stack([c[:, 0] + t * (c[:, 3] - c[:, 0]),
                             c[:, 1] + t * (c[:, 4] - c[:, 1]), np.full(4, z)], axis=1))
    return world_points(grid, np.concatenate(pts), exaggeration)


def demo_wells(grid: CornerPointGrid) -> list[WellPath]:
    """Two deviated wells through the grid, in grid coordinates, for the demo.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
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


# --- simulation wells (restart files) ------------------------------------------------------------
#: colours of simulation wells by type (as ResInsight: producers green, water injectors blue,
#: gas injectors red); shut wells and completions are grey
SIM_WELL_COLORS = {"producer": (0.10, 0.62, 0.20), "water injector": (0.12, 0.36, 0.90),
                   "gas injector": (0.88, 0.16, 0.12), "oil injector": (0.85, 0.52, 0.08),
                   "unknown": (0.30, 0.30, 0.36)}
SHUT_COLOR = (0.60, 0.60, 0.60)
#: the well head above the grid's top: this fraction of the grid's (exaggerated) thickness, and
#: at least this fraction of its horizontal diagonal
HEAD_LIFT, HEAD_LIFT_MIN = 0.25, 0.03


def cell_centres_at(grid: CornerPointGrid, cells) -> np.ndarray:
    """(n, 3) grid x, y, depth of the centres (mean of the 8 corners) of cells ``(n, 3)`` i, j, k
    (0-based), without touching the rest of the grid.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2)
    >>> c = cell_centres_at(g, [[1, 2, 1]])
    >>> bool(np.allclose(c, g.corners((slice(1, 2), slice(2, 3), slice(1, 2))).mean(axis=3)[0, 0]))
    True
    """
    ijk = np.asarray(cells, np.int64).reshape(-1, 3)
    i, j, k = ijk.T
    out = np.zeros((len(ijk), 3))
    coord = np.asarray(grid.coord, float)
    for c in range(8):  # the 8 corners
        a, b, cc = c & 1, c >> 1 & 1, c >> 2 & 1
        z = np.asarray(grid.zcorn[2 * i + a, 2 * j + b, 2 * k + cc], float)
        out += _on_pillars(coord[i + a, j + b], z)
    return out / 8.0


def _on_pillars(pil: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(n, 3) points at depths ``z`` on pillars ``pil`` (n, 6)."""
    top, bot = pil[:, :3], pil[:, 3:]
    dz = bot[:, 2] - top[:, 2]
    t = np.where(dz != 0, (z - top[:, 2]) / np.where(dz != 0, dz, 1.0), 0.0)
    return np.column_stack([top[:, 0] + t * (bot[:, 0] - top[:, 0]),
                            top[:, 1] + t * (bot[:, 1] - top[:, 1]), z])


def column_points(grid: CornerPointGrid, columns, depth) -> np.ndarray:
    """(n, 3) grid x, y, depth of the centres of columns ``(n, 2)`` i, j (0-based) at ``depth``
    (a number or one per column): the mean of the column's 4 pillars there."""
    ij = np.asarray(columns, np.int64).reshape(-1, 2)
    z = np.broadcast_to(np.asarray(depth, float), (len(ij),))
    coord = np.asarray(grid.coord, float)
    out = np.zeros((len(ij), 3))
    for a, b in ((0, 0), (1, 0), (0, 1), (1, 1)):
        out += _on_pillars(coord[ij[:, 0] + a, ij[:, 1] + b], z)
    return out / 4.0


@dataclass
class SimWellShapes:
    """What the grid view draws for the simulation wells of one report step (world
    coordinates, exaggeration applied): one pipe per well from its head above the grid through
    the centres of its completion cells, a marker per completion, a label per head."""

    names: list[str]
    paths: list[np.ndarray]
    path_colors: list[tuple]
    heads: np.ndarray
    markers: list[np.ndarray]
    marker_colors: list[np.ndarray]
    open_wells: int
    completions: int
    open_completions: int


def sim_well_shapes(grid: CornerPointGrid, wells, exaggeration: float = 1.0) -> SimWellShapes:
    """The pipes, completion markers and head points of ``wells`` (a
    :class:`~geoshade.models.wells.SimWells`), in world coordinates.

    The head of a well is above its head column, :data:`HEAD_LIFT` of the grid's exaggerated
    thickness (at least :data:`HEAD_LIFT_MIN` of its diagonal) over the grid's top; the pipe
    goes from there through the completion cells' centres in the file's order (as ResInsight
    draws simulation wells). Pipes take their type's colour (:data:`SIM_WELL_COLORS`), shut
    wells :data:`SHUT_COLOR`; markers of open completions the well's colour, shut completions
    grey.
    """
    b = display_bounds(grid)
    thick = float(b[1, 2] - b[0, 2])
    diag = float(np.hypot(*(b[1, :2] - b[0, :2])))
    lift = max(HEAD_LIFT * thick, HEAD_LIFT_MIN * diag / max(float(exaggeration), 1e-9))
    wl = list(wells)
    heads = (column_points(grid, [w.head for w in wl], b[0, 2] - lift) if wl
             else np.zeros((0, 3)))
    paths, colors, markers, mcolors = [], [], [], []
    for n, w in enumerate(wl):  # wells, not cells
        rgb = SIM_WELL_COLORS.get(w.type, SIM_WELL_COLORS["unknown"]) if w.open else SHUT_COLOR
        centres = world_points(grid, cell_centres_at(grid, w.cells), exaggeration)
        stub = (world_points(grid, column_points(grid, [w.head], b[0, 2]), exaggeration)
                if not len(centres) else centres)   # no completion: down to the grid's top
        paths.append(np.vstack([world_points(grid, heads[n:n + 1], exaggeration), stub]))
        colors.append(rgb)
        if len(centres):
            markers.append(centres)
            on = np.asarray(w.cell_open, bool) & bool(w.open)
            mcolors.append(np.where(on[:, None], rgb, SHUT_COLOR))
    return SimWellShapes(
        names=[w.name for w in wl], paths=paths, path_colors=colors,
        heads=world_points(grid, heads, exaggeration) if wl else np.zeros((0, 3)),
        markers=markers, marker_colors=mcolors,
        open_wells=sum(bool(w.open) for w in wl),
        completions=int(sum(len(w.cells) for w in wl)),
        open_completions=int(sum(int(np.count_nonzero(np.asarray(w.cell_open) & w.open))
                                 for w in wl)))
