"""Stack-based geological models: per X–Y column, an ordered run of intervals of one material.

A :class:`StackModel` is the paper's stack-based representation of terrains (SBRT): a regular
grid of ``nx × ny`` columns; each column holds, bottom to top, intervals ``(start, code)``. One
compact layout (CSR, like ``scipy.sparse``):

==========  ======================  =========================================================
name        shape, dtype            meaning
==========  ======================  =========================================================
offsets     (ncols + 1,) int64      column ``c``'s intervals are ``offsets[c]:offsets[c+1]``;
                                    ``offsets[0] == 0``, non-decreasing, ``offsets[-1] == n``
starts      (n,) float32            start (bottom) height of each interval, in *levels*
                                    above the model bottom ``origin[2]`` (one level =
                                    ``spacing[2]``); strictly increasing within a column,
                                    inside ``[0, nlevels)``
codes       (n,) int32              material code (a key of ``legend``) or :data:`EMPTY`
                                    (air, a cave, a gap in a borehole log)
borehole    (ncols,) bool           column holds a borehole log (the paper's flag)
log_base    (ncols,) float32        in a borehole column, the level where the log starts:
                                    intervals starting at or above it come from the log,
                                    those below from the model (0: the column is all log)
==========  ======================  =========================================================

Columns are numbered ``c = ix + nx * iy`` (x fastest, like a C-order ``(ny, nx)`` array).
Interval ``i`` spans ``[starts[i], starts[i+1])`` when ``i + 1`` is in the same column, else
``[starts[i], nlevels)``. Below a column's first start the column is empty; a column with no
interval is empty. A voxel model converts to exactly one canonical stack per column (no two
neighbours with the same code, no leading EMPTY interval), so its interval count is the number of
runs of equal values in the column, not counting a leading run of empties.

World position of level ``h`` of column ``(ix, iy)``: ``origin + (ix, iy, h) * spacing`` (the
column's lower-left corner); vertical exaggeration is a rendering matter, not a model one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from geoshade.errors import InputError
from geoshade.models import reprs
from geoshade.models.convert import convert

#: material code of an empty interval (air, cave, gap): never a legend code
EMPTY = -1
#: most materials a legend may hold (the GPU layouts store ``index + 1`` as an exact fp16)
MAX_MATERIALS = 2046


def _where(name: str) -> str:
    return f"{name}: " if name else ""


@dataclass
class Legend:
    """Material legend: code → name and RGBA colour.

    codes: (m,) int32       material codes, sorted, unique, none equal to EMPTY
    names: tuple of str     one name per code
    rgba:  (m, 4) uint8     one colour per code (alpha is the default opacity)

    Examples
    --------
    >>> lg = Legend.from_codes([3, 1])
    >>> lg.codes.tolist(), lg.names
    ([1, 3], ('code 1', 'code 3'))
    >>> lg.index_of(np.array([3, -1, 1])).tolist()   # palette index: 0 = empty
    [2, 0, 1]
    """

    codes: np.ndarray
    names: tuple[str, ...]
    rgba: np.ndarray

    def __post_init__(self) -> None:
        codes = np.asarray(self.codes)
        if codes.ndim != 1 or not (np.issubdtype(codes.dtype, np.integer) or codes.size == 0):
            raise InputError(f"legend codes: expected a 1D integer array, got {codes.dtype} "
                             f"shape {codes.shape}")
        codes = codes.astype(np.int32)
        rgba = np.asarray(self.rgba)
        names = tuple(str(n) for n in self.names)
        if rgba.shape != (codes.size, 4):
            raise InputError(f"legend rgba: expected shape ({codes.size}, 4), got {rgba.shape}")
        if len(names) != codes.size:
            raise InputError(f"legend names: expected {codes.size} names, got {len(names)}")
        if (codes == EMPTY).any():
            raise InputError(f"legend codes: {EMPTY} is reserved for empty intervals")
        if codes.size > MAX_MATERIALS:
            raise InputError(f"legend: {codes.size} materials; at most {MAX_MATERIALS} fit the "
                             "GPU layouts")
        order = np.argsort(codes, kind="stable")
        codes, rgba = codes[order], rgba[order]
        names = tuple(names[i] for i in order)
        if codes.size and (np.diff(codes) == 0).any():
            dup = int(codes[1:][np.diff(codes) == 0][0])
            raise InputError(f"legend codes: code {dup} appears twice")
        self.codes = codes
        self.names = names
        self.rgba = np.ascontiguousarray(np.clip(rgba, 0, 255).astype(np.uint8))

    @classmethod
    def from_codes(cls, codes, seed: int = 0) -> Legend:
        """A legend for ``codes`` with generated names and distinct colours."""
        codes = np.unique(np.asarray(codes, np.int64))
        codes = codes[codes != EMPTY].astype(np.int32)
        rng = np.random.default_rng(seed)
        hue = (np.arange(codes.size) * 0.61803398875 + rng.random()) % 1.0
        rgb = _hsv_to_rgb(hue, 0.55, 0.9)
        rgba = np.concatenate([rgb, np.full((codes.size, 1), 255, np.uint8)], axis=1)
        return cls(codes, tuple(f"code {int(c)}" for c in codes), rgba)

    def __len__(self) -> int:
        return int(self.codes.size)

    def index_of(self, codes) -> np.ndarray:
        """Palette index of each code: 0 for EMPTY, ``1 + position`` in the legend otherwise.

        Raises InputError for a code that is not in the legend.
        """
        c = np.asarray(codes)
        if self.codes.size == 0:
            pos_c, known = np.zeros(c.shape, np.int64), np.zeros(c.shape, bool)
        else:
            pos_c = np.minimum(np.searchsorted(self.codes, c), self.codes.size - 1)
            known = self.codes[pos_c] == c
        bad = ~known & (c != EMPTY)
        if bad.any():
            missing = np.unique(c[bad])[:10].tolist()
            raise InputError(f"material codes {missing} are not in the legend "
                             f"(it has {self.codes.tolist()[:20]})")
        return np.where(c == EMPTY, 0, pos_c + 1).astype(np.int32)

    def name_of(self, code: int) -> str:
        return self.names[int(self.index_of(np.array([code]))[0]) - 1]

    def to_dict(self) -> dict:
        """JSON-friendly ``{"codes": [...], "names": [...], "rgba": [[r, g, b, a], ...]}``."""
        return {"codes": self.codes.tolist(), "names": list(self.names),
                "rgba": self.rgba.tolist()}


def _hsv_to_rgb(h, s, v) -> np.ndarray:
    h = np.asarray(h, float)
    i = np.floor(h * 6).astype(int) % 6
    f = h * 6 - np.floor(h * 6)
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    vv = np.full_like(h, v)
    r = np.choose(i, [vv, q, np.full_like(h, p), np.full_like(h, p), t, vv])
    g = np.choose(i, [t, vv, vv, q, np.full_like(h, p), np.full_like(h, p)])
    b = np.choose(i, [np.full_like(h, p), np.full_like(h, p), t, vv, vv, q])
    return (np.stack([r, g, b], axis=1) * 255).round().astype(np.uint8)


def _column_ids(offsets: np.ndarray) -> np.ndarray:
    """(n,) int64: the column of each interval."""
    counts = np.diff(offsets)
    return np.repeat(np.arange(counts.size, dtype=np.int64), counts)


@dataclass(repr=False)
class StackModel:
    """A stack-based model (see the module docstring for the layout and its contracts).

    Parameters
    ----------
    offsets : (ncols + 1,) int
    starts : (n,) float
    codes : (n,) int
    shape : (nx, ny)
        Columns along x and y.
    nlevels : int
        Height of the model in levels; the last interval of a column ends there.
    legend : Legend, optional
        Default: generated from the codes present.
    origin : (x0, y0, z0)
        World position of column (0, 0)'s lower-left corner at level 0.
    spacing : (dx, dy, dz)
        Column size and level height, in ``unit``.
    borehole : (ncols,) bool, optional
        Default: no borehole column.
    crs : str
        Coordinate reference system if known (``"EPSG:28992"``), else ``""``.

    Raises
    ------
    InputError
        A shape or dtype that breaks the contract, non-monotonic starts inside a column, a start
        outside ``[0, nlevels)``, or a code missing from the legend; the message names the column.

    Examples
    --------
    >>> m = StackModel(offsets=[0, 2, 2], starts=[0, 3], codes=[7, EMPTY], shape=(2, 1),
    ...                nlevels=5)
    >>> m.ncols, m.nintervals, m.counts().tolist(), m.column_tops().tolist()
    (2, 2, [2, 0], [3.0, 0.0])
    >>> StackModel(offsets=[0, 2], starts=[2, 1], codes=[7, 8], shape=(1, 1), nlevels=5)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: intervals: column 0 (x 0, y 0): interval 1 starts at 1, ...
    """

    offsets: np.ndarray
    starts: np.ndarray
    codes: np.ndarray
    shape: tuple[int, int]
    nlevels: int
    legend: Legend | None = None
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    borehole: np.ndarray | None = None
    crs: str = ""
    unit: str = ""
    name: str = ""
    meta: dict = field(default_factory=dict)
    log_base: np.ndarray | None = None

    def __post_init__(self) -> None:
        w = _where(self.name)
        try:
            nx, ny = (int(v) for v in self.shape)
        except (TypeError, ValueError):
            raise InputError(f"{w}shape: expected (nx, ny), got {self.shape!r}") from None
        if nx < 1 or ny < 1:
            raise InputError(f"{w}shape: expected nx, ny >= 1, got ({nx}, {ny})")
        self.shape = (nx, ny)
        ncols = nx * ny
        self.nlevels = int(self.nlevels)
        if self.nlevels < 1:
            raise InputError(f"{w}nlevels: expected >= 1, got {self.nlevels}")
        off = np.asarray(self.offsets)
        if off.shape != (ncols + 1,) or not np.issubdtype(off.dtype, np.integer):
            raise InputError(f"{w}offsets: expected ({ncols + 1},) integers for {nx}×{ny} "
                             f"columns, got {off.dtype} shape {off.shape}")
        off = off.astype(np.int64)
        starts = np.asarray(self.starts)
        codes = np.asarray(self.codes)
        n = starts.size
        if starts.ndim != 1 or codes.shape != starts.shape:
            raise InputError(f"{w}starts, codes: expected two (n,) arrays, got shapes "
                             f"{starts.shape} and {codes.shape}")
        if off[0] != 0 or off[-1] != n or (np.diff(off) < 0).any():
            raise InputError(f"{w}offsets: expected 0 = offsets[0] <= ... <= offsets[-1] = "
                             f"{n} (the number of intervals), got {off[0]} ... {off[-1]}")
        if n and not np.issubdtype(codes.dtype, np.integer):
            fc = codes.astype(np.float64)
            if not np.isfinite(fc).all() or (fc != np.round(fc)).any():
                raise InputError(f"{w}codes: expected integer material codes, got {codes.dtype}")
        codes = codes.astype(np.int32)
        starts = starts.astype(np.float32)
        if n and not np.isfinite(starts).all():
            raise InputError(f"{w}starts: expected finite heights, got NaN or inf")
        col = _column_ids(off)
        if n:
            out = (starts < 0) | (starts >= self.nlevels)
            if out.any():
                i = int(np.argmax(out))
                raise InputError(f"{w}intervals: {self._col_text(col[i])}: interval "
                                 f"{i - off[col[i]]} starts at {starts[i]:g}, outside "
                                 f"[0, {self.nlevels}) levels")
            same = col[1:] == col[:-1]
            bad = same & (starts[1:] <= starts[:-1])
            if bad.any():
                i = int(np.argmax(bad)) + 1
                k = i - off[col[i]]
                raise InputError(f"{w}intervals: {self._col_text(col[i])}: interval {k} "
                                 f"starts at {starts[i]:g}, not above the start "
                                 f"{starts[i - 1]:g} of interval {k - 1} (non-monotonic or "
                                 "overlapping)")
        if self.legend is None:
            self.legend = Legend.from_codes(codes)
        elif not isinstance(self.legend, Legend):
            raise InputError(f"{w}legend: expected a Legend, got {type(self.legend).__name__}")
        else:
            try:
                self.legend.index_of(np.unique(codes))  # raises for unknown codes
            except InputError as err:   # the file's name first
                raise InputError(f"{w}{err}") from None
        bh = (np.zeros(ncols, bool) if self.borehole is None
              else np.asarray(self.borehole))
        if bh.shape != (ncols,):
            raise InputError(f"{w}borehole: expected ({ncols},) bool, got shape {bh.shape}")
        self.borehole = bh.astype(bool)
        base = (np.zeros(ncols, np.float32) if self.log_base is None
                else np.asarray(self.log_base, np.float32))
        if base.shape != (ncols,) or not np.isfinite(base).all():
            raise InputError(f"{w}log_base: expected ({ncols},) finite levels, got shape "
                             f"{base.shape}")
        self.log_base = np.where(self.borehole, base, 0.0).astype(np.float32)
        sp = tuple(float(s) for s in self.spacing)
        if len(sp) != 3 or not all(np.isfinite(sp)) or min(sp) <= 0:
            raise InputError(f"{w}spacing: expected 3 positive numbers (dx, dy, dz), got "
                             f"{self.spacing}")
        og = tuple(float(s) for s in self.origin)
        if len(og) != 3 or not all(np.isfinite(og)):
            raise InputError(f"{w}origin: expected 3 finite numbers (x0, y0, z0), got "
                             f"{self.origin}")
        self.offsets, self.starts, self.codes = off, starts, codes
        self.spacing, self.origin = sp, og
        self.crs, self.unit, self.name = str(self.crs), str(self.unit), str(self.name)

    def __repr__(self) -> str:
        """Sizes, bounds, materials, notes (no arrays; like xarray's repr).

        >>> print(StackModel([0, 1, 2], [0.0, 1.0], [1, 2], (2, 1), 3, name="m"))
        <StackModel 'm'>
        Columns:    2×1 (2, 0 from boreholes), 3 levels
        Intervals:  2 (at most 1 a column)
        Bounds:     x 0–2, y 0–1, z 0–3
        Materials:  code 1, code 2
        """
        assert self.legend is not None and self.borehole is not None  # set by __post_init__
        nx, ny = self.shape
        b = self.bounds()
        return reprs.block("StackModel", self.name, [
            ("Columns", f"{nx}×{ny} ({reprs.count(nx * ny)}, "
                        f"{reprs.count(int(self.borehole.sum()))} from boreholes), "
                        f"{self.nlevels} levels"),
            ("Intervals", f"{reprs.count(self.nintervals)} (at most {self.max_intervals} "
                          "a column)"),
            ("Bounds", reprs.span(b[0], b[1], unit=self.unit)),
            ("CRS", str(self.crs)),
            ("Materials", reprs.names(self.legend.names)),
            ("Notes", "; ".join(str(n) for n in self.meta.get("notes") or ())),
        ])

    def _col_text(self, c) -> str:
        c = int(c)
        return f"column {c} (x {c % self.shape[0]}, y {c // self.shape[0]})"

    # --- sizes ----------------------------------------------------------------------------------
    @property
    def ncols(self) -> int:
        return self.shape[0] * self.shape[1]

    @property
    def nintervals(self) -> int:
        return int(self.starts.size)

    def counts(self) -> np.ndarray:
        """(ncols,) int64: intervals per column."""
        return np.diff(self.offsets)

    @property
    def max_intervals(self) -> int:
        return int(self.counts().max(initial=0))

    def column_ids(self) -> np.ndarray:
        """(n,) int64: the column of each interval."""
        return _column_ids(self.offsets)

    def ends(self) -> np.ndarray:
        """(n,) float32: the end (top) of each interval, in levels."""
        e = np.empty_like(self.starts)
        if e.size:
            e[:-1] = self.starts[1:]
            last = self.offsets[1:][self.counts() > 0] - 1
            e[last] = self.nlevels
        return e

    def column_tops(self) -> np.ndarray:
        """(ncols,) float32: top of each column's highest non-empty interval (0 if none)."""
        top = np.zeros(self.ncols, np.float32)
        full = self.codes != EMPTY
        if full.any():
            np.maximum.at(top, self.column_ids()[full], self.ends()[full])
        return top

    def occupied_levels(self) -> tuple[float, float]:
        """(lo, hi): the vertical range holding non-empty intervals (levels); (0, 0) if none."""
        full = self.codes != EMPTY
        if not full.any():
            return 0.0, 0.0
        return float(self.starts[full].min()), float(self.ends()[full].max())

    def bounds(self) -> np.ndarray:
        """(2, 3) float: world min/max corner of the whole model (no exaggeration)."""
        sp, og = np.asarray(self.spacing), np.asarray(self.origin)
        return np.stack([og, og + np.array([*self.shape, self.nlevels]) * sp])

    @property
    def nbytes(self) -> int:
        """Bytes of the in-memory arrays (offsets, starts, codes, borehole)."""
        assert self.borehole is not None and self.log_base is not None  # set by __post_init__
        return int(self.offsets.nbytes + self.starts.nbytes + self.codes.nbytes
                   + self.borehole.nbytes + self.log_base.nbytes)

    def log_intervals(self) -> np.ndarray:
        """(n,) bool: intervals that come from a borehole log."""
        assert self.borehole is not None and self.log_base is not None  # set by __post_init__
        col = self.column_ids()
        return self.borehole[col] & (self.starts >= self.log_base[col])

    # --- construction from layers ---------------------------------------------------------------
    @classmethod
    def from_layers(cls, shape, nlevels, column, bottom, top, code, **kw) -> StackModel:
        """Build from layers ``(column, bottom, top, code)`` in levels, e.g. borehole logs.

        Layers of a column may come in any order; gaps between layers become EMPTY intervals
        and the space above a column's highest layer becomes one EMPTY interval (when below
        ``nlevels``).

        Raises
        ------
        InputError
            ``top <= bottom`` (non-monotonic), two layers of a column that overlap, or a layer
            outside ``[0, nlevels]``.

        Examples
        --------
        >>> m = StackModel.from_layers((2, 1), 10, column=[1, 1], bottom=[2, 5], top=[4, 6],
        ...                            code=[3, 4])
        >>> m.starts.tolist(), m.codes.tolist(), m.offsets.tolist()
        ([2.0, 4.0, 5.0, 6.0], [3, -1, 4, -1], [0, 0, 4])
        """
        nx, ny = (int(v) for v in shape)
        ncols = nx * ny
        where = _where(kw.get("name", ""))
        col = np.asarray(column, np.int64).ravel()
        # compared as stored (float32), so that no gap or layer thinner than that resolution
        # appears between two layers that touch
        lo = np.asarray(bottom, np.float64).ravel().astype(np.float32)
        hi = np.asarray(top, np.float64).ravel().astype(np.float32)
        cd = np.asarray(code).ravel()
        if not (col.size == lo.size == hi.size == cd.size):
            raise InputError(f"{where}layers: column, bottom, top and code need the same length")
        if col.size and (col.min() < 0 or col.max() >= ncols):
            raise InputError(f"{where}layers: column index outside 0..{ncols - 1}")
        bad = ~(hi > lo)
        if bad.any():
            i = int(np.argmax(bad))
            raise InputError(f"{where}layers: layer {i} in column {col[i]} has top {hi[i]:g} <= "
                             f"bottom {lo[i]:g} (non-monotonic)")
        out = (lo < 0) | (hi > nlevels)
        if out.any():
            i = int(np.argmax(out))
            raise InputError(f"{where}layers: layer {i} in column {col[i]} spans "
                             f"[{lo[i]:g}, {hi[i]:g}], outside [0, {nlevels}] levels")
        order = np.lexsort((lo, col))
        col, lo, hi, cd = col[order], lo[order], hi[order], cd[order]
        same = col[1:] == col[:-1]
        over = same & (lo[1:] < hi[:-1])
        if over.any():
            i = int(np.argmax(over))
            raise InputError(f"{where}layers: in column {col[i]} the layer [{lo[i + 1]:g}, "
                             f"{hi[i + 1]:g}] overlaps [{lo[i]:g}, {hi[i]:g}] (overlapping)")
        # each layer gives (start=lo, code); a gap above it (next start > top, or column end
        # with top < nlevels) gives (start=top, EMPTY)
        nxt_lo = np.where(np.append(same, False), np.append(lo[1:], np.inf), np.inf)
        gap = (hi < nxt_lo) & (hi < nlevels)
        n_out = col.size + int(gap.sum())
        pos = np.arange(col.size) + np.concatenate([[0], np.cumsum(gap)[:-1]])
        s = np.empty(n_out, np.float32)
        c = np.empty(n_out, np.int64)
        k = np.empty(n_out, np.int64)
        s[pos], c[pos], k[pos] = lo, cd, col
        gpos = pos[gap] + 1
        s[gpos], c[gpos], k[gpos] = hi[gap], EMPTY, col[gap]
        offsets = np.concatenate([[0], np.cumsum(np.bincount(k, minlength=ncols))])
        return cls(offsets=offsets, starts=s, codes=c, shape=(nx, ny), nlevels=nlevels, **kw)

    def canonical(self) -> StackModel:
        """The same model with neighbouring intervals of one code merged (fewer intervals).

        >>> StackModel([0, 3], [0, 1, 2], [4, 4, 5], (1, 1), 3).canonical().codes.tolist()
        [4, 5]
        """
        col = self.column_ids()
        keep = np.ones(self.nintervals, bool)
        keep[1:] = (col[1:] != col[:-1]) | (self.codes[1:] != self.codes[:-1])
        if keep.all():
            return self
        offsets = np.concatenate([[0], np.cumsum(np.bincount(col[keep], minlength=self.ncols))])
        return StackModel(offsets=offsets, starts=self.starts[keep], codes=self.codes[keep],
                          shape=self.shape, nlevels=self.nlevels, legend=self.legend,
                          origin=self.origin, spacing=self.spacing, borehole=self.borehole,
                          crs=self.crs, unit=self.unit, name=self.name, meta=dict(self.meta),
                          log_base=self.log_base)

    def replace_columns(self, columns, other: StackModel, flag_boreholes: bool = False,
                        log_base=None) -> StackModel:
        """A new model whose ``columns`` take their intervals from ``other`` (same grid).

        With ``flag_boreholes`` the columns become borehole columns whose log starts at
        ``log_base`` (levels, one per column; default 0: all of it).

        Examples
        --------
        >>> a = StackModel([0, 1, 2], [0, 0], [1, 1], (2, 1), 4)
        >>> b = StackModel([0, 0, 2], [0, 2], [2, EMPTY], (2, 1), 4,
        ...                legend=Legend.from_codes([1, 2]))
        >>> m = a.replace_columns([1], b, flag_boreholes=True)
        >>> m.codes.tolist(), m.borehole.tolist()
        ([1, 2, -1], [False, True])
        """
        if tuple(other.shape) != tuple(self.shape) or other.nlevels != self.nlevels:
            raise InputError("replace_columns: the other model must have the same grid")
        cols = np.unique(np.asarray(columns, np.int64))
        take = np.zeros(self.ncols, bool)
        take[cols] = True
        ca, cb = self.column_ids(), other.column_ids()
        keep_a, keep_b = ~take[ca], take[cb]
        k = np.concatenate([ca[keep_a], cb[keep_b]])
        s = np.concatenate([self.starts[keep_a], other.starts[keep_b]])
        c = np.concatenate([self.codes[keep_a], other.codes[keep_b]])
        order = np.argsort(k, kind="stable")
        offsets = np.concatenate([[0], np.cumsum(np.bincount(k, minlength=self.ncols))])
        assert self.legend is not None and other.legend is not None  # set by __post_init__
        assert self.borehole is not None and other.borehole is not None
        assert self.log_base is not None and other.log_base is not None
        legend = merge_legends(self.legend, other.legend)
        bh = self.borehole.copy()
        base = self.log_base.copy()
        bh[cols] = flag_boreholes or other.borehole[cols]
        base[cols] = other.log_base[cols] if log_base is None else np.asarray(log_base)
        return StackModel(offsets=offsets, starts=s[order], codes=c[order], shape=self.shape,
                          nlevels=self.nlevels, legend=legend, origin=self.origin,
                          spacing=self.spacing, borehole=bh, crs=self.crs, unit=self.unit,
                          name=self.name, meta=dict(self.meta), log_base=base)

    # --- conversions (geoshade.api; models import nothing above them) --------------------------
    def to_pyvista(self, **options):
        """This stack model as a PyVista ``UnstructuredGrid`` of its intervals, exact for any
        heights (:func:`geoshade.to_pyvista`; options of
        :func:`geoshade.io.interop.pyvista_io.stacks_to_pyvista`)."""

        return convert("to_pyvista", self, **options)

def merge_legends(a: Legend, b: Legend) -> Legend:
    """Codes of both; ``a`` wins where both have a code."""
    extra = ~np.isin(b.codes, a.codes)
    return Legend(np.concatenate([a.codes, b.codes[extra]]),
                  (*a.names, *(n for n, e in zip(b.names, extra, strict=True) if e)),
                  np.concatenate([a.rgba, b.rgba[extra]]))


@dataclass
class BoreholeLogs:
    """Borehole logs as a table of layers (one row per layer).

    borehole: (n,) str      borehole identifier
    x, y:     (n,) float    borehole position (world, the model's CRS)
    top:      (n,) float    top of the layer, world height (metres above the datum)
    bottom:   (n,) float    bottom of the layer, world height, below ``top``
    code:     (n,) int32    material code

    Examples
    --------
    >>> logs = BoreholeLogs(["B1", "B1"], [5, 5], [5, 5], [0.0, -2.0], [-2.0, -3.5], [1, 2])
    >>> logs.nboreholes, len(logs)
    (1, 2)
    """

    borehole: np.ndarray
    x: np.ndarray
    y: np.ndarray
    top: np.ndarray
    bottom: np.ndarray
    code: np.ndarray
    legend: Legend | None = None
    name: str = ""

    def __post_init__(self) -> None:
        self.borehole = np.asarray(self.borehole).astype(str)
        n = self.borehole.size
        for f in ("x", "y", "top", "bottom"):
            a = np.asarray(getattr(self, f), np.float64).ravel()
            if a.size != n:
                raise InputError(f"{_where(self.name)}boreholes {f}: expected {n} values, got "
                                 f"{a.size}")
            if not np.isfinite(a).all():
                raise InputError(f"{_where(self.name)}boreholes {f}: NaN or inf in a layer")
            setattr(self, f, a)
        code = np.asarray(self.code).ravel()
        if code.size != n:
            raise InputError(f"{_where(self.name)}boreholes code: expected {n} values")
        self.code = code.astype(np.int32)

    def __len__(self) -> int:
        return int(self.borehole.size)

    def __repr__(self) -> str:
        codes = np.unique(self.code).size if len(self) else 0
        return (f"BoreholeLogs({self.name!r}, {self.nboreholes} boreholes, {len(self)} layers, "
                f"{codes} codes)")

    @property
    def nboreholes(self) -> int:
        return int(np.unique(self.borehole).size)
