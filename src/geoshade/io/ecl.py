"""ECLIPSE / OPM Flow binary output: EGRID (geometry), INIT (static properties), UNRST (report
steps), read through :mod:`resfo`.

INIT and UNRST store cell arrays for the **active** cells only (in file order); they are mapped
to all cells here: floats get NaN, integers 0 in inactive cells.

Report steps of a large UNRST are not read at once: :func:`load_case` puts an
:class:`UnrstIndex` in ``grid.meta["unrst"]``.  It is a callable ``read_step(k, keyword) ->
(nx, ny, nz) array`` that seeks to the one array it needs; ``grid.meta["step_keywords"]`` lists
the keywords.  ``grid.steps`` works either way: for a small UNRST (up to ``eager_bytes``) it
holds arrays, for a large one it holds :class:`LazyStep` mappings that read an array when it is
indexed (``grid.steps[k]["SWAT"]``; the last few are cached).  :func:`step_property` reads a
step property with one-line errors for a missing step or keyword.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import resfo

from geoshade.errors import InputError
from geoshade.models import CornerPointGrid
from geoshade.progress import Progress, resolve

#: load all report steps into ``grid.steps`` when they take at most this many bytes
EAGER_BYTES = 256 << 20
#: INIT/UNRST arrays that are not cell properties even when their length matches
_NOT_CELL = frozenset({"INTEHEAD", "LOGIHEAD", "DOUBHEAD", "TABDIMS", "TAB", "SEQNUM",
                       "TRANNNC", "ICON", "SCON", "XCON", "IWEL", "SWEL", "XWEL", "ZWEL",
                       "IGRP", "SGRP", "XGRP", "ZGRP", "ISEG", "RSEG", "IUAD", "IUAP"})


def _entries(path: Path):
    """(keyword, entry) pairs of a resfo file, with one-line errors for unreadable files."""
    try:
        for e in resfo.lazy_read(str(path)):
            yield e.read_keyword().strip(), e
    except resfo.ResfoParsingError as err:
        raise InputError(f"{path}: not a readable ECLIPSE binary file ({err})") from None


def read_egrid(path) -> CornerPointGrid:
    """Read the main grid of an EGRID file (COORD, ZCORN, ACTNUM, MAPAXES, GRIDUNIT).

    Local grid refinements and NNCs after the main grid's ENDGRID are ignored.

    Returns
    -------
    CornerPointGrid
        COORD float64 (the file's float32 values), ZCORN float32, ACTNUM uint8, properties
        empty, ``meta`` with ``format`` "EGRID", ``source``, ``mapunits``.

    Examples
    --------
    >>> import numpy as np, os, tempfile, resfo
    >>> f = os.path.join(tempfile.mkdtemp(), "ONE.EGRID")
    >>> head = np.zeros(100, np.int32); head[:4] = (1, 1, 1, 1)
    >>> coord = np.array([0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1],
    ...                  np.float32)
    >>> zc = np.array([0, 0, 0, 0, 1, 1, 1, 1], np.float32)
    >>> resfo.write(f, [("GRIDHEAD", head), ("COORD   ", coord), ("ZCORN   ", zc),
    ...                 ("ACTNUM  ", np.ones(1, np.int32)), ("ENDGRID ", np.zeros(0, np.int32))])
    >>> read_egrid(f).dims
    (1, 1, 1)
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    got: dict = {}
    for kw, e in _entries(p):
        if kw == "ENDGRID":
            break
        if kw in ("GRIDHEAD", "COORD", "ZCORN", "ACTNUM", "MAPAXES", "GRIDUNIT", "MAPUNITS"):
            got[kw] = e.read_array()
    if "GRIDHEAD" not in got:
        raise InputError(f"{path}: GRIDHEAD: not found; expected an EGRID file")
    head = got["GRIDHEAD"]
    if int(head[0]) != 1:
        raise InputError(f"{path}: GRIDHEAD: grid type {int(head[0])} is not supported; "
                         "expected 1 (corner point)")
    nx, ny, nz = (int(v) for v in head[1:4])
    n = nx * ny * nz
    for kw, want, what in (("COORD", 6 * (nx + 1) * (ny + 1), "(6·(nx+1)·(ny+1))"),
                           ("ZCORN", 8 * n, "(2·nx·2·ny·2·nz)"), ("ACTNUM", n, "(nx·ny·nz)")):
        if kw not in got:
            if kw == "ACTNUM":
                continue
            raise InputError(f"{path}: {kw}: not found; expected {want} values {what}")
        if got[kw].size != want:
            raise InputError(f"{path}: {kw}: expected {want} values {what} for GRIDHEAD "
                             f"{nx}×{ny}×{nz}, got {got[kw].size}")
    coord = np.asarray(got["COORD"], np.float64).reshape(ny + 1, nx + 1, 6).transpose(1, 0, 2)
    zcorn = _native(got.pop("ZCORN")).reshape((2 * nx, 2 * ny, 2 * nz), order="F")
    actnum = None
    if "ACTNUM" in got:
        actnum = np.asarray(got["ACTNUM"] != 0, np.uint8).reshape((nx, ny, nz), order="F")

    def word(kw):
        v = got.get(kw)
        return v[0].decode(errors="replace").strip() if v is not None and len(v) else ""

    return CornerPointGrid(coord=coord, zcorn=zcorn, actnum=actnum,
                           mapaxes=got.get("MAPAXES"), units=word("GRIDUNIT"), name=str(p),
                           meta={"format": "EGRID", "source": str(p),
                                 "mapunits": word("MAPUNITS")})


def _native(a: np.ndarray) -> np.ndarray:
    """The file's big-endian array in native byte order, swapped in place (no copy)."""
    if a.dtype.byteorder in ("=", "|") or a.dtype.isnative:
        return a
    a.byteswap(inplace=True)
    return a.view(a.dtype.newbyteorder("="))


def _check_head(path, head, grid: CornerPointGrid) -> None:
    nx, ny, nz = (int(v) for v in head[8:11])
    nact = int(head[11])
    if (nx, ny, nz) != grid.dims or nact != grid.nactive:
        raise InputError(f"{path}: INTEHEAD: the file is for a {nx}×{ny}×{nz} grid with {nact} "
                         f"active cells; expected {'×'.join(map(str, grid.dims))} with "
                         f"{grid.nactive} (the EGRID's)")


def _to_cells(arr: np.ndarray, grid: CornerPointGrid, mask: np.ndarray) -> np.ndarray | None:
    """An active-cell (or all-cell) array -> (nx, ny, nz) F-order; None if it is neither."""
    a = np.asarray(arr)
    if a.dtype.kind not in "fi":
        return None
    dt = np.float32 if a.dtype.kind == "f" and a.dtype.itemsize <= 4 else \
        (np.float64 if a.dtype.kind == "f" else np.int32)
    if a.size == grid.ncells:
        return a.astype(dt).reshape(grid.dims, order="F")
    if a.size != mask.sum() or a.size == 0:
        return None
    full = np.full(grid.ncells, np.nan if a.dtype.kind == "f" else 0, dt)
    full[mask] = a
    return full.reshape(grid.dims, order="F")


def read_init(path, grid: CornerPointGrid) -> dict:
    """Static cell properties of an INIT file (PORO, PERMX, NTG, FIPNUM, ...), on all cells.

    Arrays of the active cells are mapped to all cells (NaN / 0 in inactive cells); arrays of
    all cells (e.g. PORV) are kept as they are.

    Examples
    --------
    >>> import numpy as np, os, tempfile, resfo
    >>> from geoshade.models import CornerPointGrid
    >>> i, j = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    >>> coord = np.stack([i, j, 0 * i, i, j, 0 * i + 1], -1)  # 3 x 2 x 1 cells
    >>> zc = np.zeros((6, 4, 2), np.float32); zc[..., 1] = 1
    >>> g = CornerPointGrid(coord, zc, actnum=np.array([1, 1, 1, 1, 0, 1]).reshape(3, 2, 1))
    >>> head = np.zeros(411, np.int32); head[8:12] = (3, 2, 1, g.nactive)
    >>> f = os.path.join(tempfile.mkdtemp(), "C.INIT")
    >>> resfo.write(f, [("INTEHEAD", head), ("PORO    ", np.arange(g.nactive, dtype=np.float32))])
    >>> p = read_init(f, g)["PORO"]
    >>> int(np.isnan(p).sum()), float(np.nansum(p)) == sum(range(g.nactive))
    (1, True)
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    mask = grid.active.reshape(-1, order="F")
    props: dict = {}
    for kw, e in _entries(p):
        if kw == "INTEHEAD":
            _check_head(p, e.read_array(), grid)
            continue
        if kw in _NOT_CELL or e.read_length() not in (grid.ncells, grid.nactive):
            continue
        if e.read_type() not in (b"REAL", b"DOUB", b"INTE"):
            continue
        arr = _to_cells(e.read_array(), grid, mask)
        if arr is not None:
            props[kw] = arr
    return props


class UnrstIndex:
    """Where each report step's cell arrays lie in a UNRST file; ``index(k, keyword)`` reads one.

    Attributes
    ----------
    path : Path
    dates : list of str      ISO date of each report step (from INTEHEAD)
    seqnum : list of int     the file's SEQNUM of each step
    keywords : list of str   cell keywords found (SWAT, SGAS, PRESSURE, ...)
    offsets : list of dict   keyword -> byte offset of its entry, per step
    """

    def __init__(self, path, grid: CornerPointGrid, keywords=None):
        self.path = Path(path)
        if not self.path.is_file():
            raise InputError(f"{path}: no such file")
        self.grid = grid
        self.dims = grid.dims
        want = None if keywords is None else {str(k).upper() for k in keywords}
        self.dates: list[str] = []
        self.seqnum: list[int] = []
        self.offsets: list[dict] = []
        found: dict[str, None] = {}
        sizes = (grid.ncells, grid.nactive)
        for kw, e in _entries(self.path):
            if kw == "SEQNUM":
                self.seqnum.append(int(e.read_array()[0]))
                self.offsets.append({})
                self.dates.append("")
            elif kw == "INTEHEAD" and self.offsets:
                head = e.read_array()
                _check_head(self.path, head, grid)
                d, m, y = (int(v) for v in head[64:67])
                self.dates[-1] = f"{y:04d}-{m:02d}-{d:02d}" if y > 0 else ""
            elif (self.offsets and kw not in _NOT_CELL and e.read_length() in sizes
                  and e.read_type() in (b"REAL", b"DOUB", b"INTE")
                  and (want is None or kw in want)):
                self.offsets[-1][kw] = e.start
                found[kw] = None
        if not self.offsets:
            raise InputError(f"{path}: SEQNUM: no report steps found; expected a unified "
                             "restart file")
        self.keywords = list(found)
        if want:
            missing = sorted(want - set(found))
            if missing:
                raise InputError(f"{path}: {', '.join(missing)}: not in any report step; the "
                                 f"file has {', '.join(self.keywords) or 'no cell arrays'}")

    def __len__(self) -> int:
        return len(self.offsets)

    def cached(self, k: int, keyword: str) -> np.ndarray:
        """:meth:`__call__` keeping the last :attr:`cache_size` arrays."""
        key = (int(k), str(keyword).upper())
        cache = self.__dict__.setdefault("_cache", {})
        if key not in cache:
            while len(cache) >= self.cache_size:
                cache.pop(next(iter(cache)))
            cache[key] = self(*key)
        return cache[key]

    cache_size = 4

    def check(self, k: int, keyword: str | None = None) -> str | None:
        n = len(self.offsets)
        if not isinstance(k, int | np.integer) or not 0 <= k < n:
            raise InputError(f"{self.path}: step {k} does not exist; the file has {n} report "
                             f"steps (0-{n - 1})")
        if keyword is None:
            return None
        kw = str(keyword).upper()
        if kw not in self.offsets[k]:
            have = ", ".join(self.offsets[k]) or "no cell arrays"
            raise InputError(f"{self.path}: {kw} is not in report step {k}; it has {have}")
        return kw

    def __call__(self, k: int, keyword: str) -> np.ndarray:
        """The (nx, ny, nz) array of ``keyword`` at report step ``k`` (NaN in inactive cells)."""
        kw = self.check(k, keyword)
        with open(self.path, "rb") as fh:
            fh.seek(self.offsets[k][kw])
            e = next(resfo.lazy_read(fh, resfo.Format.UNFORMATTED))
            arr = e.read_array()
        mask = self.grid.active.reshape(-1, order="F")
        out = _to_cells(arr, self.grid, mask)
        if out is None:  # pragma: no cover - sizes were checked by the index
            raise InputError(f"{self.path}: {kw} (step {k}): unexpected length {arr.size}")
        return out

    def step(self, k: int) -> dict:
        """All indexed keywords of step ``k``."""
        self.check(k)
        return {kw: self(k, kw) for kw in self.offsets[k]}


class LazyStep(Mapping):
    """``grid.steps[k]`` of a large UNRST: keyword -> (nx, ny, nz) array, read on access."""

    def __init__(self, index: UnrstIndex, k: int):
        self.index, self.k = index, k

    def __getitem__(self, keyword: str) -> np.ndarray:
        if keyword not in self:
            raise KeyError(keyword)
        return self.index.cached(self.k, keyword)

    def __contains__(self, keyword) -> bool:
        return keyword in self.index.offsets[self.k]

    def __iter__(self):
        return iter(self.index.offsets[self.k])

    def __len__(self) -> int:
        return len(self.index.offsets[self.k])


def read_unrst(path, grid: CornerPointGrid, keywords=None, progress=None):
    """All report steps of a unified restart file, in file order.

    Parameters
    ----------
    path : str or Path
        ``.UNRST`` (unformatted).
    grid : CornerPointGrid
        The case's grid (its ACTNUM maps active-cell arrays to all cells).
    keywords : list of str, optional
        Keep only these (e.g. ``["SWAT", "PRESSURE"]``); default every cell array.
    progress : callable, optional
        ``progress(steps_read, steps_total)`` after each report step (see
        :mod:`geoshade.progress`); None: no reports.

    Returns
    -------
    steps : list of dict
        ``steps[k][keyword]`` -> (nx, ny, nz) array (NaN in inactive cells).
    dates : list of str
        ISO date of each step.
    """
    index = UnrstIndex(path, grid, keywords)
    return _read_steps(index, progress), list(index.dates)


def _read_steps(index: UnrstIndex, progress: Progress | None) -> list[dict]:
    """Every report step of ``index`` as arrays, reporting ``progress(k + 1, n)``."""
    report, n, steps = resolve(progress), len(index), []
    for k in range(n):  # report steps
        steps.append(index.step(k))
        report(k + 1, n)
    return steps


def _beside(path: Path, exts: tuple[str, ...]) -> Path | None:
    for ext in exts:
        for e in (ext, ext.lower()):
            c = path.with_suffix(e)
            if c.is_file():
                return c
    return None


def load_case(path, keywords=None, eager_bytes: int = EAGER_BYTES,
              progress: Progress | None = None) -> CornerPointGrid:
    """An ECLIPSE/OPM case from its EGRID: geometry, INIT properties and UNRST report steps.

    Parameters
    ----------
    path : str or Path
        ``CASE.EGRID``; ``CASE.INIT`` must lie beside it, ``CASE.UNRST`` may.
    keywords : list of str, optional
        UNRST keywords to index (default all cell arrays: SWAT, SGAS, PRESSURE, ...).
    eager_bytes : int
        Load the report steps into ``grid.steps`` when they take at most this many bytes;
        above, ``grid.steps`` holds :class:`LazyStep` mappings that read on access.
    progress : callable, optional
        ``progress(steps_read, steps_total)`` while the report steps are loaded (only when they
        are loaded, see ``eager_bytes``); None: no reports.

    Returns
    -------
    CornerPointGrid
        ``properties`` from INIT; ``step_dates``; ``steps`` (arrays or lazy mappings);
        ``meta["unrst"]`` an :class:`UnrstIndex` (callable ``read_step(k, keyword)``),
        ``meta["step_keywords"]``, ``meta["init"]``, ``meta["unrst_path"]``.

    Raises
    ------
    InputError
        No INIT beside the EGRID, or anything wrong in the files (one line).
    """
    p = Path(path)
    grid = read_egrid(p)
    init = _beside(p, (".INIT", ".FINIT"))
    if init is None:
        raise InputError(f"{path}: no INIT file beside the EGRID (looked for "
                         f"{p.with_suffix('.INIT').name}); a case needs EGRID + INIT")
    grid.properties = read_init(init, grid)
    grid.meta["init"] = str(init)
    unrst = _beside(p, (".UNRST",))
    if unrst is not None:
        index = UnrstIndex(unrst, grid, keywords)
        grid.meta.update(unrst=index, unrst_path=str(unrst), step_keywords=list(index.keywords),
                         unrst_seqnum=list(index.seqnum))
        grid.step_dates = list(index.dates)
        total = sum(len(o) for o in index.offsets) * grid.ncells * 4
        if total <= eager_bytes:
            grid.steps = _read_steps(index, progress)
            grid.__post_init__()
        else:
            grid.steps = [LazyStep(index, k) for k in range(len(index))]
    return grid


def step_property(grid: CornerPointGrid, k: int, name: str) -> np.ndarray:
    """Property ``name`` at report step ``k``, from ``grid.steps`` or the lazy UNRST index.

    Raises
    ------
    InputError
        A step or keyword that does not exist (one line).

    Examples
    --------
    >>> import numpy as np
    >>> from geoshade.models import CornerPointGrid
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> zc = np.zeros((2, 2, 2), np.float32); zc[..., 1] = 1
    >>> g = CornerPointGrid(coord, zc, steps=[{"SWAT": np.zeros((1, 1, 1))}] * 2, name="demo")
    >>> step_property(g, 1, "SWAT").shape
    (1, 1, 1)
    >>> step_property(g, 5, "SWAT")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: demo: step 5 does not exist; the case has 2 report steps (0-1)
    """
    index = grid.meta.get("unrst") if isinstance(grid.meta, dict) else None
    if grid.steps:
        n = len(grid.steps)
        if not isinstance(k, int | np.integer) or not 0 <= k < n:
            raise InputError(f"{grid.name}: step {k} does not exist; the case has {n} report "
                             f"steps (0-{n - 1})")
        if name in grid.steps[k]:
            return grid.steps[k][name]
        if index is None:
            raise InputError(f"{grid.name}: {name} is not in report step {k}; it has "
                             f"{', '.join(grid.steps[k]) or 'nothing'}")
    if index is None:
        raise InputError(f"{grid.name}: step {k}: the case has no report steps")
    return index(k, name)
