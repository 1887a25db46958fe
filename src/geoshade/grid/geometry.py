"""Geometry of the reservoir-grid view: IJK slices, bounds and matrices (no GL).

Coordinates: the grid's own (x, y, depth) go to the GPU relative to a local origin; the model
matrix applies MAPAXES (grid -> map x, y) and shows depth upwards-negative, scaled by the
vertical exaggeration (world z = -exaggeration * depth: shallow cells on top). Planes and camera
framing use the world without exaggeration's effect on meaning: x east, y north, z up.
"""

from __future__ import annotations

import re

import numpy as np

from geoshade.errors import InputError
from geoshade.models.grid import CornerPointGrid, WellPath

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

    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> g = synthetic_grid(4, 4, 2)
    >>> p = plane_from_clip("0,0,1,0", g)          # old: keep the deeper half
    >>> p.normal
    (0.0, 0.0, -1.0)
    """
    from geoshade.styles.options import Plane

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
    """(2, 3) grid-coordinate bounds (x, y, depth) of the pillars and the active cells' depths."""
    b = grid.bounds()
    depths = grid.active_depth_range()   # in slabs: no copy of ZCORN
    if depths is not None:
        b[0, 2], b[1, 2] = depths
    return b


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
