"""Scalar fields over time (saturation, pressure, ...) and triangle meshes.

One layout for every field: each time step is a ``(nz, ny, nx)`` array of *node* values, x
varying fastest.

- On a regular grid the node ``[k, j, i]`` sits at ``origin + (i, j, k) * spacing`` (point
  samples, as VTK's ``ImageData`` point data): the marching-cubes cells lie between nodes.
- On a rectilinear grid (``coords`` set: the node coordinates along x, y and z, each
  increasing, spacing not even, as a netCDF file's own coordinates give them) the node
  ``[k, j, i]`` sits at ``(x[i], y[j], z[k])``: the surface is placed through the nodes where
  they are, never on an even grid.
- On a corner-point grid (``grid`` set) the node ``[k, j, i]`` is the *cell* ``(i, j, k)`` of the
  grid: values are cell-centred and the surface is placed through the cell centres. The grid's
  ``[i, j, k]`` F-order arrays are taken as ``array.T``, a C-order ``(nz, ny, nx)`` view (no
  copy). ``spacing`` and ``origin`` are unused; ``active`` defaults to the grid's ACTNUM.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.models import reprs
from geoshade.models.convert import convert
from geoshade.models.grid import CornerPointGrid
from geoshade.models.names import derived_names, derived_values


def _where(name: str) -> str:
    return f"{name}: " if name else ""


def _steps_of(values, what: str, where: str) -> tuple[Any, tuple[int, int, int], int]:
    """A 3D array, a 4D array or a sequence of 3D arrays -> (indexable of steps, shape, count)."""
    shape = getattr(values, "shape", None)
    if shape is not None and not isinstance(values, list | tuple):
        if len(shape) == 3:
            return [values], (int(shape[0]), int(shape[1]), int(shape[2])), 1
        if len(shape) == 4:
            if int(shape[0]) < 1:
                raise InputError(f"{where}{what}: no time steps (shape {tuple(shape)})")
            return values, (int(shape[1]), int(shape[2]), int(shape[3])), int(shape[0])
        raise InputError(f"{where}{what}: expected (nz, ny, nx) or (time, nz, ny, nx), got "
                         f"shape {tuple(shape)}")
    if not isinstance(values, Sequence) or len(values) == 0:
        raise InputError(f"{where}{what}: expected an array or a non-empty list of 3D arrays, "
                         f"got {type(values).__name__}")
    shapes = [tuple(int(n) for n in getattr(a, "shape", ())) for a in values]
    first = shapes[0]
    if len(first) != 3:
        raise InputError(f"{where}{what} (step 0): expected a 3D (nz, ny, nx) array, got shape "
                         f"{first}")
    for k, s in enumerate(shapes):
        if s != first:
            raise InputError(f"{where}{what}: step {k} has shape {s}, step 0 has {first}; every "
                             "step must have the same shape")
    return list(values), first, len(shapes)


@dataclass
class FieldSeries:
    """One or many time steps of a scalar field, on a regular grid or a corner-point grid.

    values:     (T, nz, ny, nx) array-like, a list of T (nz, ny, nx) arrays, or one
                (nz, ny, nx) array (T = 1). numpy, memmap, zarr or dask: a step is read only
                when :meth:`step` asks for it
    spacing:    (3,) float   node spacing along (x, y, z) (regular grids; on a rectilinear
                             grid the mean spacing, for sizes only)
    origin:     (3,) float   position of node (0, 0, 0) (regular and rectilinear grids)
    coords:     (x (nx,), y (ny,), z (nz,)) float64 or None   node coordinates of a rectilinear
                grid, each strictly increasing, world z up; coordinates that are evenly
                spaced become ``spacing``/``origin`` (one layout per grid), so ``coords`` is
                None unless some axis is uneven
    grid:       CornerPointGrid or None   values are on its cells (then nx, ny, nz = grid.dims)
    active:     (nz, ny, nx) bool or None   nodes taking part; others are outside the surface
                (default: the grid's ACTNUM, or all)
    name:       quantity, e.g. "SWAT"
    unit:       unit of the values ("" if unknown)
    length_unit: unit of spacing/origin/grid coordinates ("" if unknown)
    times:      one label per step (ISO date or "step k"); default "step 0", "step 1", ...
    properties: other quantities on the same nodes and steps, name -> values (same forms as
                ``values``; T = 1 is allowed and used for every step), for colouring
    source:     the file it came from, for messages
    meta:       anything else (format, keyword, ...)

    Examples
    --------
    >>> import numpy as np
    >>> f = FieldSeries(np.zeros((3, 4, 5, 6), np.float32), spacing=(2, 2, 1), name="SWAT")
    >>> f.nsteps, f.shape_xyz, f.cells, f.step(2).dtype.name
    (3, (6, 5, 4), 60, 'float32')
    >>> f.bounds().tolist()
    [[0.0, 0.0, 0.0], [10.0, 8.0, 3.0]]
    >>> r = FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1], [0, 1], [-200, -10, -2]))
    >>> r.is_rectilinear, r.bounds()[:, 2].tolist(), r.spacing
    (True, [-200.0, -2.0], (1.0, 1.0, 99.0))
    """

    values: Any
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    grid: CornerPointGrid | None = None
    active: Any = None
    coords: Any = None
    name: str = ""
    unit: str = ""
    length_unit: str = ""
    times: list = field(default_factory=list)
    properties: dict = field(default_factory=dict)
    source: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        w = _where(self.source or self.name)
        self.values, shape, n = _steps_of(self.values, self.name or "values", w)
        self._shape, self._n = shape, n
        if min(shape) < 2:
            raise InputError(f"{w}{self.name or 'values'}: shape {shape} (nz, ny, nx) has fewer "
                             "than 2 nodes along an axis; an isosurface needs at least 2 per axis"
                             + _thin_hint(shape, self.grid))
        if self.grid is not None:
            if not isinstance(self.grid, CornerPointGrid):
                raise InputError(f"{w}grid: expected a CornerPointGrid, got "
                                 f"{type(self.grid).__name__}")
            nx, ny, nz = self.grid.dims
            if shape != (nz, ny, nx):
                raise InputError(f"{w}{self.name or 'values'}: shape {shape} (nz, ny, nx) does "
                                 f"not match the grid's {(nz, ny, nx)} cells")
            if self.active is None:
                self.active = self.grid.active.T
        sp = tuple(float(s) for s in self.spacing)
        if len(sp) != 3 or not all(np.isfinite(sp)) or min(sp) <= 0:
            raise InputError(f"{w}spacing: expected 3 positive numbers (x, y, z), got "
                             f"{self.spacing}")
        og = tuple(float(s) for s in self.origin)
        if len(og) != 3 or not all(np.isfinite(og)):
            raise InputError(f"{w}origin: expected 3 finite numbers (x, y, z), got {self.origin}")
        self.spacing, self.origin = sp, og
        if self.coords is not None:
            self._set_coords(w, shape)
        if self.active is not None:
            act = np.asarray(self.active)
            if act.shape != shape:
                raise InputError(f"{w}active: expected shape {shape} (nz, ny, nx), got "
                                 f"{act.shape}")
            self.active = act if act.dtype == np.bool_ else act != 0
        if not self.times:
            self.times = [f"step {k}" for k in range(n)]
        elif len(self.times) != n:
            raise InputError(f"{w}times: {len(self.times)} labels for {n} steps")
        self.times = [str(t) for t in self.times]
        props = {}
        self._prop_n: dict[str, int] = {}
        for pname, pvals in self.properties.items():
            steps, pshape, pn = _steps_of(pvals, pname, w)
            if pshape != shape:
                raise InputError(f"{w}{pname}: shape {pshape} (nz, ny, nx) does not match "
                                 f"{self.name or 'the field'}'s {shape}")
            if pn not in (1, n):
                raise InputError(f"{w}{pname}: {pn} steps, the field has {n}")
            props[str(pname)] = steps
            self._prop_n[str(pname)] = pn
        self.properties = props

    # --- sizes ---------------------------------------------------------------------------------
    @property
    def nsteps(self) -> int:
        return self._n

    @property
    def shape(self) -> tuple[int, int, int]:
        """Nodes per step, ``(nz, ny, nx)``."""
        return self._shape

    @property
    def shape_xyz(self) -> tuple[int, int, int]:
        nz, ny, nx = self._shape
        return (nx, ny, nz)

    @property
    def nodes(self) -> int:
        nz, ny, nx = self._shape
        return nx * ny * nz

    @property
    def cells(self) -> int:
        """Marching-cubes cells per step: ``(nx-1)(ny-1)(nz-1)``."""
        nz, ny, nx = self._shape
        return (nx - 1) * (ny - 1) * (nz - 1)

    @property
    def is_cornerpoint(self) -> bool:
        return self.grid is not None

    @property
    def is_rectilinear(self) -> bool:
        """Nodes at uneven coordinates along some axis (``coords`` set)."""
        return self.coords is not None

    def _set_coords(self, w: str, shape) -> None:
        """Check ``coords`` against the shape; evenly spaced ones become spacing/origin."""
        if self.grid is not None:
            raise InputError(f"{w}coords: a field on a corner-point grid takes its positions "
                             "from the grid")
        try:
            axes = [np.asarray(c, dtype=np.float64).ravel() for c in self.coords]
        except (TypeError, ValueError):
            raise InputError(f"{w}coords: expected three 1D arrays of numbers (x, y, z)") \
                from None
        if len(axes) != 3:
            raise InputError(f"{w}coords: expected three 1D arrays (x, y, z), got {len(axes)}")
        nz, ny, nx = shape
        for name, a, n in zip("xyz", axes, (nx, ny, nz), strict=True):
            if a.size != n:
                raise InputError(f"{w}coords: {name} has {a.size} values for {n} nodes")
            if not np.isfinite(a).all():
                raise InputError(f"{w}coords: {name} has values that are not finite")
            if (np.diff(a) <= 0).any():
                raise InputError(f"{w}coords: {name} is not strictly increasing; expected node "
                                 "coordinates in increasing order")
        even = [bool(np.allclose(np.diff(a), (a[-1] - a[0]) / (a.size - 1), rtol=1e-6,
                                 atol=1e-9 * max(1.0, abs(a[-1] - a[0])))) for a in axes]
        x, y, z = axes
        self.origin = (float(x[0]), float(y[0]), float(z[0]))
        self.spacing = (float((x[-1] - x[0]) / (x.size - 1)),
                        float((y[-1] - y[0]) / (y.size - 1)),
                        float((z[-1] - z[0]) / (z.size - 1)))
        self.coords = None if all(even) else tuple(axes)

    def node_positions(self) -> np.ndarray:
        """(nz, ny, nx, 3) float64 world position (x, y, z) of every node of a regular or
        rectilinear grid (not a corner-point one: its nodes are the grid's cell centres).

        >>> import numpy as np
        >>> f = FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1], [5, 6], [-50, -10, -2]))
        >>> f.node_positions()[:, 0, 0].tolist()
        [[0.0, 5.0, -50.0], [0.0, 5.0, -10.0], [0.0, 5.0, -2.0]]
        """
        if self.grid is not None:
            raise InputError(f"{_where(self.source)}node positions of a corner-point field are "
                             "its grid's cell centres")
        x, y, z = self.axes()
        zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")
        return np.stack([xx, yy, zz], axis=-1)

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The node coordinates along x, y and z (regular or rectilinear grids).

        >>> import numpy as np
        >>> [a.tolist() for a in FieldSeries(np.zeros((2, 2, 2)), spacing=(2, 1, 1)).axes()]
        [[0.0, 2.0], [0.0, 1.0], [0.0, 1.0]]
        """
        if self.coords is not None:
            return tuple(np.asarray(c, np.float64) for c in self.coords)  # type: ignore
        nz, ny, nx = self._shape
        return tuple(o + np.arange(n) * s for o, s, n in  # type: ignore[return-value]
                     zip(self.origin, self.spacing, (nx, ny, nz), strict=True))

    # --- access --------------------------------------------------------------------------------
    def check_step(self, step) -> int:
        """``step`` as an index 0..T-1 (negative counts from the end); else one clear error.

        >>> import numpy as np
        >>> FieldSeries(np.zeros((2, 2, 2, 2)), name="S").check_step(-1)
        1
        """
        n = self.nsteps
        try:
            k = int(step)
        except (TypeError, ValueError):
            raise InputError(f"{_where(self.source)}step: expected an integer, got "
                             f"{step!r}") from None
        if k != step or not -n <= k < n:
            raise InputError(f"{_where(self.source)}step {step} does not exist: "
                             f"{self.name or 'the field'} has {n} step{'s' if n != 1 else ''} "
                             f"(0..{n - 1})")
        return k % n

    def _read(self, steps, k: int, what: str) -> np.ndarray:
        a = steps[k]
        if hasattr(a, "compute"):
            a = a.compute()
        a = np.asarray(a)
        if a.shape != self._shape:
            raise InputError(f"{_where(self.source)}{what} step {k}: shape {a.shape}, expected "
                             f"{self._shape}")
        if a.dtype.kind not in "fiub":
            raise InputError(f"{_where(self.source)}{what} step {k}: expected numbers, got "
                             f"dtype {a.dtype}")
        return a

    def step(self, k=0) -> np.ndarray:
        """The values of step ``k`` as a ``(nz, ny, nx)`` float32 array (read now)."""
        k = self.check_step(k)
        return np.asarray(self._read(self.values, k, self.name or "values"), dtype=np.float32)

    def property_step(self, name: str, k=0) -> np.ndarray:
        """Another quantity (``properties[name]``) at step ``k`` as float32 ``(nz, ny, nx)``."""
        if name not in self.properties:
            have = ", ".join(self.properties) or "none"
            raise InputError(f"{_where(self.source)}property {name!r} is not available; "
                             f"this field has: {have}")
        k = self.check_step(k)
        steps = self.properties[name]
        k = k if self._prop_n[name] > 1 else 0
        return np.asarray(self._read(steps, k, name), dtype=np.float32)

    def __repr__(self) -> str:
        """Sizes, steps, unit, grid, properties (no values; like xarray's repr).

        >>> print(FieldSeries(np.zeros((3, 2, 2, 2), np.float32), name="SWAT",
        ...                   times=["2000-01-01", "2000-02-01", "2000-03-01"]))
        <FieldSeries 'SWAT'>
        Dimensions:  x: 2, y: 2, z: 2 (8 nodes)
        Steps:       3 (2000-01-01 … 2000-03-01)
        Bounds:      x 0–1, y 0–1, z 0–1
        """
        nx, ny, nz = self.shape_xyz
        b = self.bounds()
        on = "cells" if self.grid is not None else "nodes"
        return reprs.block("FieldSeries", self.name, [
            ("Dimensions", f"x: {nx}, y: {ny}, z: {nz} ({reprs.count(nx * ny * nz)} {on})"),
            ("Steps", reprs.steps_text(self.nsteps, self.times)),
            ("Unit", self.unit),
            ("Bounds", reprs.span(b[0], b[1], ("x", "y", "depth" if self.grid is not None
                                           else "z"), self.length_unit)),
            ("Spacing", self._uneven_text()),
            ("Grid", (self.grid.name or "corner-point grid") if self.grid is not None else ""),
            ("Properties", reprs.names(self.properties)),
            ("Source", self.source),
        ])

    def _uneven_text(self) -> str:
        if self.coords is None:
            return ""
        parts = []
        for name, c in zip("xyz", self.coords, strict=True):
            d = np.diff(np.asarray(c, np.float64))
            if not np.allclose(d, d.mean(), rtol=1e-6):
                parts.append(f"{name} {d.min():.4g}–{d.max():.4g}")
        return "uneven: " + ", ".join(parts)

    # --- geometry ------------------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        """(2, 3) min/max corner: the nodes' box (regular) or the grid's extent (corner-point).

        Independent of the step and the level, so framing a camera on it keeps every picture of
        the series pixel-aligned.
        """
        if self.grid is not None:
            return np.asarray(self.grid.bounds(), dtype=float)
        if self.coords is not None:
            return np.array([[c[0] for c in self.coords], [c[-1] for c in self.coords]],
                            dtype=float)
        nz, ny, nx = self._shape
        og, sp = np.asarray(self.origin), np.asarray(self.spacing)
        return np.stack([og, og + (np.array([nx, ny, nz]) - 1) * sp])

    def index_to_world(self) -> np.ndarray:
        """4×4 matrix from node index space ``(i, j, k)`` to world (regular grids; a
        rectilinear grid's nodes are at :meth:`axes`, so this is refused for it).

        >>> import numpy as np
        >>> FieldSeries(np.zeros((2, 2, 2)), spacing=(2, 3, 4), origin=(1, 1, 1)
        ...             ).index_to_world()[:3, 3].tolist()
        [1.0, 1.0, 1.0]
        """
        if self.coords is not None:
            raise InputError(f"{_where(self.source)}the nodes are not evenly spaced; use "
                             "node_positions() or axes()")
        m = np.diag([*self.spacing, 1.0])
        m[:3, 3] = self.origin
        return m

    # --- conversions (geoshade.api; models import nothing above them) --------------------------
    def to_pyvista(self, **options):
        """This field as a PyVista ``ImageData`` (node values as point data) or its grid's
        ``ExplicitStructuredGrid`` (:func:`geoshade.to_pyvista`; options of
        :func:`geoshade.io.interop.pyvista_io.field_to_pyvista`)."""

        return convert("to_pyvista", self, **options)

    def to_xarray(self, name: str | None = None):
        """This field as xarray: a ``DataArray`` ``(time, z, y, x)`` (nodes) or ``(time, k, j, i)``
        (grid cells) (:func:`geoshade.to_xarray`)."""

        return convert("to_xarray", self, name=name)


def _thin_hint(shape, grid) -> str:
    """What to do with a field one node thick: a corner-point grid is drawn by ``grid
    render``; a 2D map is not a volume."""
    if grid is not None:
        nx, ny, nz = grid.dims
        return (f"; the grid is {nx}×{ny}×{nz} cells, one cell thick along an axis: draw its "
                "cells with geoshade grid render (geoshade.view(grid))")
    return ""


@dataclass
class TriangleMesh:
    """An indexed triangle mesh (e.g. an isosurface captured from the GPU).

    vertices: (n, 3) float32|float64  positions (world coordinates)
    faces:    (m, 3) int64            vertex indices, counter-clockwise seen from the side the
                                      normals point to
    normals:  (n, 3) float32 or None  unit vertex normals
    values:   (n,) float32 or None    a scalar per vertex (e.g. the colour property)
    name:     str

    Examples
    --------
    >>> import numpy as np
    >>> m = TriangleMesh(np.eye(3), [[0, 1, 2]])
    >>> m.n_vertices, m.n_faces, round(m.area(), 4)
    (3, 1, 0.866)
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray | None = None
    values: np.ndarray | None = None
    name: str = ""

    def __post_init__(self) -> None:
        w = _where(self.name)
        v = np.asarray(self.vertices)
        if v.ndim != 2 or v.shape[1] != 3 or v.dtype.kind != "f":
            raise InputError(f"{w}vertices: expected (n, 3) float, got {v.shape} {v.dtype}")
        f = np.asarray(self.faces, dtype=np.int64).reshape(-1, 3)
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise InputError(f"{w}faces: indices must lie in 0..{len(v) - 1}")
        self.vertices, self.faces = v, f
        if self.normals is not None:
            nrm = np.asarray(self.normals, dtype=np.float32)
            if nrm.shape != v.shape:
                raise InputError(f"{w}normals: expected shape {v.shape}, got {nrm.shape}")
            self.normals = nrm
        if self.values is not None:
            val = np.asarray(self.values, dtype=np.float32).ravel()
            if val.shape != (len(v),):
                raise InputError(f"{w}values: expected {len(v)} values, got {val.shape}")
            self.values = val

    def __repr__(self) -> str:
        """``<TriangleMesh 'iso'>`` with its counts, bounds and what it carries.

        >>> print(TriangleMesh(np.eye(3), [[0, 1, 2]], name="iso"))
        <TriangleMesh 'iso'>
        Triangles:  1 (3 vertices)
        Bounds:     x 0–1, y 0–1, z 0–1
        """
        v = np.asarray(self.vertices)
        carries = [n for n, a in (("normals", self.normals), ("values", self.values))
                   if a is not None]
        return reprs.block("TriangleMesh", self.name, [
            ("Triangles", f"{reprs.count(self.n_faces)} ({reprs.count(self.n_vertices)} vertices)"),
            ("Bounds", reprs.span(v.min(axis=0), v.max(axis=0)) if len(v) else ""),
            ("Carries", ", ".join(carries)),
        ])

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    def triangles(self) -> np.ndarray:
        """``(m, 3, 3)`` vertex positions of every face."""
        return np.asarray(self.vertices)[self.faces]

    def area(self) -> float:
        t = self.triangles().astype(np.float64)
        if not len(t):
            return 0.0
        return float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]),
                                          axis=1).sum())

    # --- conversions (geoshade.api; models import nothing above them) --------------------------
    def to_pyvista(self, **options):
        """This mesh as a PyVista ``PolyData`` (:func:`geoshade.to_pyvista`; options of
        :func:`geoshade.io.interop.pyvista_io.mesh_to_pyvista`)."""

        return convert("to_pyvista", self, **options)


class GridSteps(Sequence):
    """(T, nz, ny, nx) view of one report-step keyword of a corner-point grid (derived ones such
    as SOIL too); a step is read when indexed (by ``read(grid, k, name)`` when given, e.g. a
    reader's own lookup), so a FieldSeries over it stays lazy.

    >>> import numpy as np
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2)
    >>> s = GridSteps(g, "SWAT")
    >>> s.shape, bool((s[1] == np.asarray(g.steps[1]["SWAT"]).T).all())
    ((4, 2, 3, 4), True)
    """

    def __init__(self, grid: CornerPointGrid, name: str, nsteps: int | None = None,
                 read=None):
        self.grid, self.name, self._read = grid, name, read
        nx, ny, nz = grid.dims
        self.shape = (len(grid.steps) if nsteps is None else int(nsteps), nz, ny, nx)

    def __len__(self) -> int:
        return self.shape[0]

    def __getitem__(self, k):

        if self._read is not None:
            return np.asarray(self._read(self.grid, int(k), self.name)).T
        if self.name in derived_names(self.grid):
            return derived_values(self.grid, self.name, int(k)).T
        return np.asarray(self.grid.steps[int(k)][self.name]).T
