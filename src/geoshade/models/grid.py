"""Corner-point reservoir grids (ECLIPSE GRDECL/EGRID geometry), faults and wells.

Layout: every array is indexed ``[i, j, k]`` (the issue's and xtgeo's shapes) and stored in
Fortran order, i varying fastest, which is the order of the GRDECL/EGRID files themselves: a
reader wraps the file's flat array with ``reshape(shape, order="F")`` and copies nothing.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from geoshade.errors import InputError
from geoshade.models import reprs
from geoshade.models.convert import convert
from geoshade.models.reprs import points_text

#: largest |value| of COORD and ZCORN taken as a coordinate; beyond it (1e20, 3e38: fill
#: values) or NaN/inf a value is not a usable coordinate and the grid is refused
MAX_COORDINATE = 1e10
#: cells per slab in the slab-wise checks (bounded temporaries on 1e8-cell grids)
_SLAB_CELLS = 1 << 22
_PILLAR_PARTS = ("top x", "top y", "top z", "bottom x", "bottom y", "bottom z")


def _usable(a: np.ndarray) -> np.ndarray:
    """True where ``a`` is finite and within ±:data:`MAX_COORDINATE` (False for NaN)."""
    with np.errstate(invalid="ignore"):
        return np.abs(a) <= MAX_COORDINATE


def _all_usable(a: np.ndarray) -> bool:
    """Fast check (min and max, no temporaries): every value usable."""
    lo, hi = float(np.min(a)), float(np.max(a))
    return bool(-MAX_COORDINATE <= lo and hi <= MAX_COORDINATE)  # False for NaN


def _zslabs(nz2: int, per_layer: int):
    """Ranges of corner layers (even bounds) holding about :data:`_SLAB_CELLS` values."""
    step = max(2, 2 * (_SLAB_CELLS // max(1, per_layer)))
    for c0 in range(0, nz2, step):
        yield c0, min(nz2, c0 + step)


def _first_unusable(z: np.ndarray) -> tuple[int, float] | None:
    """(file index, value) of the first unusable ZCORN value in file (F) order, or None."""
    if _all_usable(z):
        return None
    per = z.shape[0] * z.shape[1]
    for c0, c1 in _zslabs(z.shape[2], per):
        bad = ~_usable(np.asarray(z[:, :, c0:c1]))
        if bad.any():
            q = int(np.flatnonzero(bad.ravel(order="F"))[0])
            return c0 * per + q, float(np.asarray(z[:, :, c0:c1]).ravel(order="F")[q])
    return None  # pragma: no cover - the fast check saw one


def _finite_range(a: np.ndarray) -> tuple[float, float]:
    """(min, max) over the usable values of ``a`` (NaN, NaN if there are none)."""
    if _all_usable(a):
        return float(np.min(a)), float(np.max(a))
    ok = a[_usable(a)]
    return (float(ok.min()), float(ok.max())) if ok.size else (np.nan, np.nan)


def _check(name: str, arr, shape, where: str, kinds="fiub") -> np.ndarray:
    a = np.asarray(arr) if not hasattr(arr, "shape") else arr
    if tuple(a.shape) != tuple(shape):
        raise InputError(f"{where}{name}: expected shape {tuple(shape)}, got {tuple(a.shape)}")
    if np.dtype(a.dtype).kind not in kinds:
        raise InputError(f"{where}{name}: expected a numeric array, got dtype {a.dtype}")
    return a


@dataclass
class Fault:
    """A named fault: the cell faces it consists of.

    name:  str
    faces: (n, 4) int32  rows ``i, j, k, face`` (0-based cells; face 0..5 = I+ J+ K+ I- J- K-,
           i.e. the FAULTS keyword's X, Y, Z, X-, Y-, Z-)
    """

    name: str
    faces: np.ndarray

    def __post_init__(self) -> None:
        self.faces = np.asarray(self.faces, np.int32).reshape(-1, 4)

    def __repr__(self) -> str:
        return f"Fault({self.name!r}, {len(self.faces)} faces)"


#: the media of a dual-porosity or dual-permeability grid, in the files' order
MEDIA = ("matrix", "fracture")


@dataclass
class Medium:
    """One medium of a dual-porosity or dual-permeability grid (ECLIPSE ``DUALPORO``,
    ``DUALPERM``): its active cells, properties and report steps on the shared geometry.

    name:       "matrix" or "fracture"
    actnum:     (nx, ny, nz) bool|int   the medium's active cells, F-order
    properties: name -> (nx, ny, nz)    the medium's INIT properties
    steps:      report steps, ``steps[k][name]`` -> (nx, ny, nz)
    meta:       what replaces the grid's meta keys when this medium is selected (``unrst``:
                the medium's step reader)
    """

    name: str
    actnum: np.ndarray
    properties: dict = field(default_factory=dict)
    steps: list = field(default_factory=list)
    meta: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        return (f"Medium({self.name!r}, {int(np.count_nonzero(np.asarray(self.actnum)))} "
                f"active, {len(self.properties)} properties, {len(self.steps)} steps)")


@dataclass
class Refinement:
    """A local grid refinement (ECLIPSE LGR, ``CARFIN``): cells of its own inside a box of
    host cells of its parent grid.

    name:     str                   the LGR's name
    parent:   str                   "" when its host cells are the global grid's, else the
                                    parent LGR's name
    hostnum:  (nx, ny, nz) int64    0-based index (F order: i fastest) of each refined cell's
                                    host cell in the parent grid, F-order
    host_box: ((i0, i1), (j0, j1), (k0, k1))  0-based inclusive box of the host cells
    grid:     CornerPointGrid       the refined cells: geometry, ACTNUM, properties, steps
    """

    name: str
    parent: str
    hostnum: np.ndarray
    host_box: tuple
    grid: CornerPointGrid

    def __post_init__(self) -> None:
        self.hostnum = np.asarray(self.hostnum, np.int64)
        if self.hostnum.shape != self.grid.dims:
            raise InputError(f"LGR {self.name}: HOSTNUM: expected shape {self.grid.dims} (the "
                             f"LGR's cells), got {self.hostnum.shape}")
        self.host_box = tuple((int(a), int(b)) for a, b in self.host_box)

    @property
    def dims(self) -> tuple[int, int, int]:
        """(nx, ny, nz) of the refined cells."""
        return self.grid.dims

    def box_text(self) -> str:
        """The host box, 1-based: ``I=2..3 J=2..3 K=1``."""
        return " ".join(f"{a}={lo + 1}" if lo == hi else f"{a}={lo + 1}..{hi + 1}"
                        for a, (lo, hi) in zip("IJK", self.host_box, strict=True))

    def label(self) -> str:
        """``LGR1 4×4×1 in I=2..3 J=2..3 K=1`` (the parent named when it is not global).

        >>> import numpy as np
        >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1)], float)
        >>> g = CornerPointGrid(coord, np.repeat([[[0.0, 1.0]]], 2, 0).repeat(2, 1))
        >>> Refinement("L1", "", np.zeros((1, 1, 1)), ((1, 1), (0, 2), (4, 4)), g).label()
        'L1 1×1×1 in I=2 J=1..3 K=5'
        """
        where = f" of {self.parent}" if self.parent else ""
        return f"{self.name} {'×'.join(map(str, self.dims))} in {self.box_text()}{where}"

    def cell_label(self, i: int, j: int, k: int) -> str:
        """A refined cell (0-based, local) named as a pick names it: ``LGR1 I=1 J=2 K=1 (host
        I=2 J=2 K=1)`` (the host from ``HOSTNUM``; needs :meth:`placed`'s ``parent_dims``)."""
        hi, hj, hk = np.unravel_index(int(self.hostnum[i, j, k]),
                                      self.grid.meta["parent_dims"], order="F")
        return (f"{self.name} I={i + 1} J={j + 1} K={k + 1} (host I={hi + 1} J={hj + 1} "
                f"K={hk + 1})")

    def placed(self, parent: CornerPointGrid) -> Refinement:
        """This refinement with its grid placed, named and measured as ``parent`` (the grid
        hosting it) is: the parent's map axes and units where its own are missing, the
        parent's unit system, report-step numbers and name, and ``meta["parent_dims"]``
        (the host grid's (nx, ny, nz), for host cell numbers). Views of a refinement (the
        grid part's cells, the iso part's surfaces) draw it in the parent's frame."""
        child = self.grid
        inherit = {k: parent.meta[k] for k in ("unit_system", "unrst_seqnum", "name")
                   if k in parent.meta and k not in child.meta}
        child = dataclasses.replace(
            child, mapaxes=child.mapaxes if child.mapaxes is not None else parent.mapaxes,
            units=child.units or parent.units,
            meta={**inherit, **child.meta, "parent_dims": parent.dims})
        return dataclasses.replace(self, grid=child)

    def __repr__(self) -> str:
        return f"Refinement({self.label()!r})"


@dataclass
class CornerPointGrid:
    """An ECLIPSE corner-point grid of ``nx × ny × nz`` cells.

    coord:      (nx+1, ny+1, 6) float   pillar top (x, y, z) and bottom (x, y, z), F-order
    zcorn:      (2nx, 2ny, 2nz) float   corner depths: cell (i, j, k) corner (a, b, c) is at
                                        ``zcorn[2i+a, 2j+b, 2k+c]``, F-order
    actnum:     (nx, ny, nz) bool|int   active cells (default: all), F-order
    mapaxes:    (6,) float or None      MAPAXES x1 y1 x0 y0 x2 y2 (grid -> map coordinates)
    properties: name -> (nx, ny, nz)    cell properties (float or int), F-order; inactive
                                        cells hold whatever the file said (often 0 or NaN)
    steps:      report-step properties, ``steps[k][name]`` -> (nx, ny, nz); empty if static
    step_dates: one ISO date string per report step ("" where unknown)
    faults:     list of Fault
    units:      "METRES", "FEET", ... ("" if unknown)
    name:       file it came from, for messages
    meta:       what the reader knew (format, source, restart files, ``notes``: sentences a
                picture or ``info`` shows, such as which files would add properties)
    refinements: list of Refinement   local grid refinements (LGRs): refined cells inside
                                      host cells of this grid (or of another LGR)
    medium:     "" (one medium), or "matrix" / "fracture": the medium that ``actnum``,
                ``properties`` and ``steps`` hold in a dual-porosity/permeability grid
    dual_media: medium name -> Medium, every medium of a dual grid (empty otherwise); see
                :meth:`select_medium`
    """

    coord: np.ndarray
    zcorn: np.ndarray
    actnum: np.ndarray | None = None
    mapaxes: np.ndarray | None = None
    properties: dict = field(default_factory=dict)
    steps: list = field(default_factory=list)
    step_dates: list = field(default_factory=list)
    faults: list = field(default_factory=list)
    units: str = ""
    name: str = ""
    meta: dict = field(default_factory=dict)
    refinements: list = field(default_factory=list)
    medium: str = ""
    dual_media: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        w = f"{self.name}: " if self.name else ""
        c = self.coord
        if getattr(c, "ndim", 0) != 3 or c.shape[2] != 6 or min(c.shape[:2]) < 2:
            raise InputError(f"{w}COORD: expected shape (nx+1, ny+1, 6) with nx, ny >= 1, "
                             f"got {getattr(c, 'shape', None)}")
        nx, ny = c.shape[0] - 1, c.shape[1] - 1
        z = self.zcorn
        if getattr(z, "ndim", 0) != 3 or z.shape[0] != 2 * nx or z.shape[1] != 2 * ny \
                or z.shape[2] % 2 or z.shape[2] < 2:
            raise InputError(f"{w}ZCORN: expected shape (2nx, 2ny, 2nz) = ({2 * nx}, {2 * ny}, "
                             f"2nz), got {getattr(z, 'shape', None)}")
        _check("COORD", c, c.shape, w, "f")
        _check("ZCORN", z, z.shape, w, "f")
        nz = z.shape[2] // 2
        if self.actnum is None:
            self.actnum = np.ones((nx, ny, nz), dtype=bool, order="F")
        _check("ACTNUM", self.actnum, (nx, ny, nz), w, "biu")
        if self.mapaxes is not None:
            self.mapaxes = np.asarray(self.mapaxes, float).ravel()
            if self.mapaxes.size != 6:
                raise InputError(f"{w}MAPAXES: expected 6 numbers, got {self.mapaxes.size}")
        for name, arr in self.properties.items():
            _check(name, arr, (nx, ny, nz), w)
        self.check_steps()
        self._check_parts(w, (nx, ny, nz))
        if isinstance(c, np.ndarray) and isinstance(z, np.ndarray):
            self.check_geometry()

    def _check_parts(self, w: str, dims) -> None:
        """Refinements host cells of this grid; every medium has the grid's shape."""
        n = int(np.prod(dims))
        names = set()
        for r in self.refinements:
            if not isinstance(r, Refinement):
                raise InputError(f"{w}refinements: expected Refinement objects, got "
                                 f"{type(r).__name__}")
            if r.name.upper() in names:
                raise InputError(f"{w}LGR {r.name}: two local grids have that name")
            names.add(r.name.upper())
            if not r.parent and r.hostnum.size and not (
                    0 <= int(r.hostnum.min()) and int(r.hostnum.max()) < n):
                raise InputError(f"{w}LGR {r.name}: HOSTNUM: host cells "
                                 f"{int(r.hostnum.min()) + 1}..{int(r.hostnum.max()) + 1} "
                                 f"outside the grid's {n} cells")
        for name, m in self.dual_media.items():
            _check(f"ACTNUM ({name})", m.actnum, dims, w, "biu")
            for pname, arr in m.properties.items():
                _check(f"{pname} ({name})", arr, dims, w)
        if self.dual_media and self.medium not in self.dual_media:
            raise InputError(f"{w}medium {self.medium!r}: expected one of "
                             f"{', '.join(self.dual_media)}")

    def check_steps(self) -> None:
        """Every report-step array has the grid's shape (else one line naming it)."""
        w = f"{self.name}: " if self.name else ""
        for k, step in enumerate(self.steps):
            for name, arr in step.items():
                _check(f"{name} (step {k})", arr, self.dims, w)

    def check_geometry(self) -> None:
        """Refuse COORD or ZCORN values that are NaN, infinite or beyond ±:data:`MAX_COORDINATE`
        (fill values such as 1e20 or 3e38): one line naming the keyword, the first bad value's
        0-based index in the file's array and its 1-based cell (ZCORN) or pillar (COORD).

        Called at construction for numpy arrays (lazy arrays are not read here).

        Examples
        --------
        >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
        ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
        >>> zc = np.zeros((2, 2, 2), np.float32); zc[..., 1] = 1; zc[1, 0, 1] = np.inf
        >>> CornerPointGrid(coord, zc, name="G")
        Traceback (most recent call last):
        ...
        geoshade.errors.InputError: G: ZCORN: value inf at index 5 (cell i=1 j=1 k=1) is not \
a finite depth (expected |z| <= 1e+10)
        """
        w = f"{self.name}: " if self.name else ""
        c = np.asarray(self.coord)
        if not _all_usable(c):
            flat = c.transpose(1, 0, 2).reshape(-1)  # the file's order: i fastest, 6 a pillar
            q = int(np.flatnonzero(~_usable(flat))[0])
            p, part = divmod(q, 6)
            j, i = divmod(p, c.shape[0])
            raise InputError(f"{w}COORD: value {float(flat[q]):g} at index {q} (pillar "
                             f"i={i + 1} j={j + 1}, {_PILLAR_PARTS[part]}) is not a finite "
                             f"coordinate (expected |v| <= {MAX_COORDINATE:g})")
        bad = _first_unusable(self.zcorn)
        if bad is not None:
            q, v = bad
            a, b, cc = np.unravel_index(q, self.zcorn.shape, order="F")
            raise InputError(f"{w}ZCORN: value {v:g} at index {q} (cell i={a // 2 + 1} "
                             f"j={b // 2 + 1} k={cc // 2 + 1}) is not a finite depth (expected "
                             f"|z| <= {MAX_COORDINATE:g})")

    def inverted_cells(self) -> tuple[int, tuple[int, int, int] | None]:
        """Active cells whose bottom lies above their top at a corner (a bottom depth smaller
        than the top depth on the same pillar): how many, and the first in file order (0-based
        i, j, k) or None.

        Examples
        --------
        >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
        ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
        >>> zc = np.zeros((2, 2, 2), np.float32); zc[..., 0] = 1    # bottom 0 above top 1
        >>> CornerPointGrid(coord, zc).inverted_cells()
        (1, (0, 0, 0))
        """
        z = self.zcorn
        nx, ny, nz = self.dims
        act = self.active
        count, first = 0, None
        for c0, c1 in _zslabs(2 * nz, 4 * nx * ny):
            s = np.asarray(z[:, :, c0:c1])
            inv = s[:, :, 1::2] < s[:, :, 0::2]
            cell = inv[0::2, 0::2] | inv[1::2, 0::2] | inv[0::2, 1::2] | inv[1::2, 1::2]
            cell &= act[:, :, c0 // 2:c1 // 2]
            n = int(np.count_nonzero(cell))
            if n and first is None:
                q = int(np.flatnonzero(cell.ravel(order="F"))[0])
                i, j, k = np.unravel_index(q, cell.shape, order="F")
                first = (int(i), int(j), int(k) + c0 // 2)
            count += n
        return count, first

    # --- sizes -------------------------------------------------------------------------------
    def __repr__(self) -> str:
        """Sizes, bounds, properties, steps, faults (no arrays; like xarray's repr).

        >>> import numpy as np
        >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1)], float)
        >>> print(CornerPointGrid(coord, np.repeat([[[0.0, 1.0]]], 2, 0).repeat(2, 1),
        ...                       properties={"PORO": np.zeros((1, 1, 1))}, name="g.grdecl"))
        <CornerPointGrid 'g.grdecl'>
        Dimensions:  nx: 1, ny: 1, nz: 1 (1 cells, 1 active)
        Bounds:      x 0–1, y 0–1, depth 0–1
        Properties:  PORO float64
        """
        nx, ny, nz = self.dims
        exact = isinstance(self.zcorn, np.ndarray) and self.zcorn.size <= reprs.EXACT_BOUNDS
        if exact:
            b = self.active_bounds()
        else:   # the pillars' extent: no pass over the corner depths of a huge grid
            c = np.asarray(self.coord, float).reshape(-1, 6)
            b = np.array([[c[:, [q, q + 3]].min() for q in range(3)],
                          [c[:, [q, q + 3]].max() for q in range(3)]])
        unit = {"METRES": "m", "FEET": "ft", "CM": "cm"}.get(str(self.units).upper(),
                                                            str(self.units).lower())
        steps = list(self.meta.get("step_keywords") or (self.steps[0] if self.steps else []))
        props = {n: reprs.dtype_name(a) for n, a in self.properties.items()}
        step_text = reprs.steps_text(len(self.steps), self.step_dates)
        return reprs.block("CornerPointGrid", self.name, [
            ("Dimensions", f"nx: {nx}, ny: {ny}, nz: {nz} ({reprs.count(self.ncells)} cells, "
                           f"{reprs.count(self.nactive)} active)"),
            ("Bounds" if exact else "Pillars", reprs.span(b[0], b[1], ("x", "y", "depth"), unit)),
            ("Properties", reprs.names(props, props)),
            ("Steps", step_text + (f": {reprs.names(steps)}" if step_text and steps else "")),
            ("Faults", f"{len(self.faults)}: {reprs.names(f.name for f in self.faults)}"
             if self.faults else ""),
            ("Map axes", "yes (MAPAXES)" if self.mapaxes is not None else ""),
            ("Wells", reprs.names(w.name for w in self.meta.get("wells") or [])),
            ("LGRs", "; ".join(x.label() for x in self.refinements)),
            ("Media", f"{', '.join(self.media)} (showing {self.medium})" if self.media else ""),
            ("Notes", "; ".join(str(n) for n in self.meta.get("notes") or ())),
        ])

    @property
    def dims(self) -> tuple[int, int, int]:
        """(nx, ny, nz)."""
        return (self.coord.shape[0] - 1, self.coord.shape[1] - 1, self.zcorn.shape[2] // 2)

    @property
    def ncells(self) -> int:
        nx, ny, nz = self.dims
        return nx * ny * nz

    @property
    def active(self) -> np.ndarray:
        """(nx, ny, nz) bool view of ACTNUM."""
        return np.asarray(self.actnum) != 0

    @property
    def nactive(self) -> int:
        if not isinstance(self.actnum, np.ndarray) and "nactive" in self.meta:
            return int(self.meta["nactive"])  # a grid store says it: ACTNUM is not read
        return int(np.count_nonzero(np.asarray(self.actnum)))

    # --- geometry ----------------------------------------------------------------------------
    def corners(self, ijk_slices=None) -> np.ndarray:
        """(nx, ny, nz, 8, 3) float64 corner points of the cells (or of a sub-block).

        Corner c = a + 2b + 4c' with a, b, c' in {0, 1} along i, j, k (k down the pillar). The
        point lies on its pillar at the corner's depth ``z`` (linear in z between pillar top
        and bottom; a vertical pillar keeps x, y).
        """
        si, sj, sk = ijk_slices or (slice(None),) * 3
        nx, ny, nz = self.dims
        i = np.arange(nx)[si]
        j = np.arange(ny)[sj]
        k = np.arange(nz)[sk]
        out = np.empty((i.size, j.size, k.size, 8, 3))
        for c in range(8):
            a, b, cc = c & 1, c >> 1 & 1, c >> 2 & 1
            z = np.asarray(self.zcorn)[np.ix_(2 * i + a, 2 * j + b, 2 * k + cc)]
            pil = np.asarray(self.coord)[np.ix_(i + a, j + b)]  # (ni, nj, 6)
            top, bot = pil[..., None, :3], pil[..., None, 3:]
            dz = bot[..., 2] - top[..., 2]
            t = np.where(dz != 0, (z - top[..., 2]) / np.where(dz != 0, dz, 1), 0.0)
            out[..., c, 0] = top[..., 0] + t * (bot[..., 0] - top[..., 0])
            out[..., c, 1] = top[..., 1] + t * (bot[..., 1] - top[..., 1])
            out[..., c, 2] = z
        return out

    def bounds(self) -> np.ndarray:
        """(2, 3) min/max corner of the pillars' and corners' extent (grid coordinates), over
        the usable values only (NaN, inf and fill values beyond ±:data:`MAX_COORDINATE` are
        left out; a grid built from files never holds them, see :meth:`check_geometry`)."""
        c = np.asarray(self.coord).reshape(-1, 6)
        (x0, x1), (y0, y1) = (_finite_range(c[:, [q, q + 3]]) for q in (0, 1))
        z0, z1 = _finite_range(np.asarray(self.zcorn))
        return np.array([[x0, y0, z0], [x1, y1, z1]])

    def active_depth_range(self) -> tuple[float, float] | None:
        """(min, max) usable corner depth of the active cells; None when no cell is active."""
        act = self.active
        if not act.any():
            return None
        nx, ny, nz = self.dims
        lo, hi = np.inf, -np.inf
        for c0, c1 in _zslabs(2 * nz, 4 * nx * ny):
            s = np.asarray(self.zcorn[:, :, c0:c1])
            a = np.repeat(np.repeat(np.repeat(act[:, :, c0 // 2:c1 // 2], 2, 0), 2, 1), 2, 2)
            v = s[a & _usable(s)]
            if v.size:
                lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
        return (lo, hi) if lo <= hi else None

    def map_transform(self) -> np.ndarray:
        """3×3 affine matrix grid (x, y, 1) -> map (x, y, 1) from MAPAXES (identity if none)."""
        if self.mapaxes is None:
            return np.eye(3)
        x1, y1, x0, y0, x2, y2 = self.mapaxes
        ex = np.array([x2 - x0, y2 - y0])
        ey = np.array([x1 - x0, y1 - y0])
        ex /= np.linalg.norm(ex) or 1.0
        ey /= np.linalg.norm(ey) or 1.0
        m = np.eye(3)
        m[:2, 0], m[:2, 1], m[:2, 2] = ex, ey, (x0, y0)
        return m

    def property_names(self) -> list[str]:
        names = list(self.properties)
        for step in self.steps[:1]:
            names += [n for n in step if n not in names]
        return names

    # --- dual media and local refinements ------------------------------------------------------
    @property
    def media(self) -> tuple[str, ...]:
        """("matrix", "fracture") for a dual-porosity/permeability grid, () otherwise."""
        return tuple(self.dual_media)

    def select_medium(self, name: str | None) -> CornerPointGrid:
        """This grid with ``actnum``, ``properties`` and ``steps`` of medium ``name``.

        None or "" keeps the medium shown; "matrix" on a grid of one medium is the grid itself.

        Raises
        ------
        InputError
            A medium the grid does not have (one line).

        Examples
        --------
        >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1)], float)
        >>> zc = np.repeat([[[0.0, 1.0]]], 2, 0).repeat(2, 1)
        >>> one = np.ones((1, 1, 1), np.uint8)
        >>> media = {"matrix": Medium("matrix", one, {"PORO": np.ones((1, 1, 1))}),
        ...          "fracture": Medium("fracture", one,
        ...                             {"PORO": np.zeros((1, 1, 1))})}
        >>> g = CornerPointGrid(coord, zc, properties=media["matrix"].properties,
        ...                     medium="matrix", dual_media=media)
        >>> g.media, float(g.select_medium("fracture").properties["PORO"][0, 0, 0])
        (('matrix', 'fracture'), 0.0)
        """
        w = f"{self.name}: " if self.name else ""
        key = str(name or "").strip().lower()
        if not key or key == self.medium:
            return self
        if not self.dual_media:
            if key == "matrix":
                return self
            raise InputError(f"{w}medium {name}: this grid has one medium (not a dual-porosity "
                             "or dual-permeability case); expected matrix")
        if key not in self.dual_media:
            raise InputError(f"{w}medium {name}: expected one of {', '.join(self.dual_media)}")
        m = self.dual_media[key]
        return dataclasses.replace(self, actnum=m.actnum, properties=m.properties,
                                   steps=m.steps, medium=key, meta={**self.meta, **m.meta})

    def refinement(self, name: str) -> Refinement:
        """The local grid refinement called ``name`` (any case); one line if there is none."""
        for r in self.refinements:
            if r.name.upper() == str(name).strip().upper():
                return r
        have = ", ".join(r.name for r in self.refinements) or "none"
        raise InputError(f"{self.name or 'grid'}: LGR {name}: no such local grid; it has {have}")

    def host_cells(self, names=None) -> np.ndarray:
        """(nx, ny, nz) bool: the cells of this grid that host a refinement (drawn as their
        refined cells by a viewer that draws refinements); of the ones ``names`` names only,
        when given."""
        out = np.zeros(self.ncells, bool)
        for r in self.refinements:
            if not r.parent and (names is None or r.name in names):
                out[r.hostnum.ravel()] = True
        return out.reshape(self.dims, order="F")

    def hosts_hidden(self, names=None) -> CornerPointGrid:
        """This grid with the host cells of its refinements inactive (a View that draws the
        refinements draws their refined cells there instead), of the ones ``names`` names
        only when given; the grid itself when it has none or they are hidden already.
        ``meta["hosts_hidden"]``: how many cells; ``meta["refinements_drawn"]``: whose.

        >>> import numpy as np
        >>> from geoshade.compute.grid.synthetic import synthetic_grid
        >>> g = synthetic_grid(2, 2, 1)
        >>> r = Refinement("L", "", np.zeros((2, 2, 2)), ((0, 0), (0, 0), (0, 0)),
        ...                synthetic_grid(2, 2, 2))
        >>> h = dataclasses.replace(g, refinements=[r]).hosts_hidden()
        >>> int(h.nactive), h.meta["refinements_drawn"]
        (3, ['L'])
        >>> int(dataclasses.replace(g, refinements=[r]).hosts_hidden([]).nactive)
        4
        """
        if not self.refinements or "hosts_hidden" in self.meta:
            return self
        drawn = [r.name for r in self.refinements if not r.parent and
                 (names is None or r.name in names)]
        hosts = self.host_cells(drawn)
        active = np.asarray(self.active, bool) & ~hosts
        return dataclasses.replace(self, actnum=active.astype(np.int32),
                                   meta={**self.meta, "hosts_hidden": int(hosts.sum()),
                                         "refinements_drawn": drawn})

    def active_bounds(self) -> np.ndarray:
        """(2, 3) min/max of the **active** cells' extent: depth over their corners, x and y over
        the pillars that bound an active column (inactive cells' corners, often 0 in ECLIPSE
        files, are left out); :meth:`bounds` when no cell is active.

        Examples
        --------
        >>> coord = np.array([[[x, 0, 0, x, 0, 1], [x, 1, 0, x, 1, 1]] for x in (0, 1, 2)],
        ...                  float)
        >>> zc = np.zeros((4, 2, 2), np.float32); zc[:2, :, 0] = 100; zc[:2, :, 1] = 110
        >>> g = CornerPointGrid(coord, zc, actnum=np.array([1, 0]).reshape(2, 1, 1))
        >>> g.bounds()[:, 2].tolist(), g.active_bounds().tolist()
        ([0.0, 110.0], [[0.0, 0.0, 100.0], [1.0, 1.0, 110.0]])
        """
        depths = self.active_depth_range()
        if depths is None:
            return self.bounds()
        cols = self.active.any(axis=2)
        pil = np.zeros((cols.shape[0] + 1, cols.shape[1] + 1), bool)
        for a in (0, 1):
            for b in (0, 1):
                pil[a:a + cols.shape[0], b:b + cols.shape[1]] |= cols
        c = np.asarray(self.coord)[pil]
        (x0, x1), (y0, y1) = (_finite_range(c[:, [q, q + 3]]) for q in (0, 1))
        return np.array([[x0, y0, depths[0]], [x1, y1, depths[1]]])

    # --- conversions (geoshade.api; models import nothing above them) --------------------------
    def to_pyvista(self, **options):
        """This grid as a PyVista ``ExplicitStructuredGrid`` (inactive cells hidden)
        (:func:`geoshade.to_pyvista`; options of
        :func:`geoshade.io.interop.pyvista_io.grid_to_pyvista`)."""

        return convert("to_pyvista", self, **options)

    def to_xarray(self, name: str | None = None):
        """This grid as xarray: a ``Dataset`` (geometry, ACTNUM, properties, report keywords), or
        the DataArray of property ``name`` (:func:`geoshade.to_xarray`)."""

        return convert("to_xarray", self, name=name)


@dataclass
class WellPath:
    """A well trajectory with optional markers.

    name:     str
    points:   (n, 3) float  trajectory x, y, z (z = depth, down positive, as in the grid)
    markers:  (m, 3) float  marker positions (e.g. completions)
    cells:    (m, 3) int    the (i, j, k) cell of each marker where known, else -1
    """

    name: str
    points: np.ndarray
    markers: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    cells: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))

    def __post_init__(self) -> None:
        self.points = np.asarray(self.points, float).reshape(-1, 3)
        self.markers = np.asarray(self.markers, float).reshape(-1, 3)
        self.cells = np.asarray(self.cells, np.int64).reshape(-1, 3)
        if len(self.points) < 1:
            raise InputError(f"well {self.name}: trajectory needs at least one point")
        if not np.all(np.isfinite(self.points)):
            raise InputError(f"well {self.name}: trajectory has NaN or infinite coordinates")

    def __repr__(self) -> str:
        """``WellPath('A', 2 points, x 0–0, y 0–0, depth 10–20, 1 markers)``."""

        marks = f", {len(self.markers)} markers" if len(self.markers) else ""
        return f"{type(self).__name__}({self.name!r}, {points_text(self.points)}{marks})"
