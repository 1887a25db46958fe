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

Damaged files (:mod:`geoshade.io.ecl_records` walks and checks every record header first): a
truncated or damaged EGRID or INIT is one error naming the file and the keyword; a truncated
UNRST (what a killed run leaves) gives its complete report steps and one warning naming the
first incomplete one.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.ecl_records import Record, RecordError, scan
from geoshade.io.grid_checks import check_grid_size, check_memory, warn_inverted
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid
from geoshade.progress import Progress, resolve

#: load all report steps into ``grid.steps`` when they take at most this many bytes
EAGER_BYTES = 256 << 20
#: INIT/UNRST arrays that are not cell properties even when their length matches
_NOT_CELL = frozenset({"INTEHEAD", "LOGIHEAD", "DOUBHEAD", "TABDIMS", "TAB", "SEQNUM",
                       "TRANNNC", "ICON", "SCON", "XCON", "IWEL", "SWEL", "XWEL", "ZWEL",
                       "IGRP", "SGRP", "XGRP", "ZGRP", "ISEG", "RSEG", "IUAD", "IUAP"})


#: EGRID keywords of the main grid that are read, and the kinds of values they must hold
_EGRID = {"GRIDHEAD": "i", "COORD": "f", "ZCORN": "f", "ACTNUM": "i", "MAPAXES": "f",
          "GRIDUNIT": "S", "MAPUNITS": "S"}
#: INTEHEAD values needed: grid size and active cells at 8-11, the date at 64-66
_INTEHEAD_DIMS, _INTEHEAD_DATE = 12, 67


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
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "an ECLIPSE EGRID file")
    recs: dict[str, Record] = {}
    last, ended = "", False
    for rec in scan(p):  # every header checked, to the end of the file, before any array
        if not ended:
            ended = rec.keyword == "ENDGRID"
            if rec.keyword in _EGRID:
                recs.setdefault(rec.keyword, rec)
            last = rec.keyword
    if "GRIDHEAD" not in recs:
        raise InputError(f"{path}: GRIDHEAD: not found; expected an EGRID file")
    head = recs["GRIDHEAD"].read("i")
    if head.size < 4:
        raise InputError(f"{path}: GRIDHEAD: expected at least 4 integers (type, NX, NY, NZ), "
                         f"got {head.size}")
    if int(head[0]) != 1:
        raise InputError(f"{path}: GRIDHEAD: grid type {int(head[0])} is not supported; "
                         "expected 1 (corner point)")
    nx, ny, nz = (int(v) for v in head[1:4])
    if min(nx, ny, nz) < 1:
        raise InputError(f"{path}: GRIDHEAD: grid size {nx}×{ny}×{nz} is not positive")
    n = nx * ny * nz
    if 32 * n > p.stat().st_size:  # 8 ZCORN values of 4 bytes a cell
        raise InputError(f"{path}: GRIDHEAD: a {nx}×{ny}×{nz} grid needs {8 * n:.3g} ZCORN "
                         f"values ({32 * n:.3g} bytes); the file has {p.stat().st_size} bytes")
    if not ended:
        raise InputError(f"{path}: ENDGRID: not found after the main grid; the file is "
                         f"truncated (it ends after {last})")
    for kw, want, what in (("COORD", 6 * (nx + 1) * (ny + 1), "(6·(nx+1)·(ny+1))"),
                           ("ZCORN", 8 * n, "(2·nx·2·ny·2·nz)"), ("ACTNUM", n, "(nx·ny·nz)")):
        if kw not in recs:
            if kw == "ACTNUM":
                continue
            raise InputError(f"{path}: {kw}: not found; expected {want} values {what}")
        if recs[kw].length != want:
            raise InputError(f"{path}: {kw}: expected {want} values {what} for GRIDHEAD "
                             f"{nx}×{ny}×{nz}, got {recs[kw].length}")
    check_grid_size(p, "GRIDHEAD", (nx, ny, nz))
    coord = np.asarray(recs["COORD"].read("f"), np.float64).reshape(ny + 1, nx + 1, 6)
    zcorn = _native(recs["ZCORN"].read("f")).reshape((2 * nx, 2 * ny, 2 * nz), order="F")
    actnum = None
    if "ACTNUM" in recs:
        actnum = np.asarray(recs["ACTNUM"].read("i") != 0, np.uint8).reshape((nx, ny, nz),
                                                                             order="F")

    def word(kw: str) -> str:
        if kw not in recs:
            return ""
        v = recs[kw].read("S")
        return bytes(v[0]).decode(errors="replace").strip() if len(v) else ""

    mapaxes = recs["MAPAXES"].read("f") if "MAPAXES" in recs else None
    grid = CornerPointGrid(coord=coord.transpose(1, 0, 2), zcorn=zcorn, actnum=actnum,
                           mapaxes=mapaxes, units=word("GRIDUNIT"), name=str(p),
                           meta={"format": "EGRID", "source": str(p),
                                 "mapunits": word("MAPUNITS")})
    warn_inverted(grid, p)
    return grid


def _native(a: np.ndarray) -> np.ndarray:
    """The file's big-endian array in native byte order, swapped in place (no copy)."""
    if a.dtype.byteorder in ("=", "|") or a.dtype.isnative:
        return a
    a.byteswap(inplace=True)
    return a.view(a.dtype.newbyteorder("="))


def _check_head(path, head, grid: CornerPointGrid, need: int = _INTEHEAD_DIMS) -> None:
    if head.size < need:
        raise InputError(f"{path}: INTEHEAD: expected at least {need} integers (ECLIPSE writes "
                         f"411), got {head.size}")
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
    if a.size not in (grid.ncells, grid.nactive) or a.size == 0:
        return None
    check_memory(grid.name, f"a cell array ({grid.ncells} values)",
                 grid.ncells * np.dtype(dt).itemsize)
    if a.size == grid.ncells:
        return a.astype(dt).reshape(grid.dims, order="F")
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
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "an ECLIPSE INIT file")
    mask = grid.active.reshape(-1, order="F")
    records = list(scan(p))  # every header checked, to the end of the file, before any array
    heads = [r for r in records if r.keyword == "INTEHEAD"]
    if not heads:
        raise InputError(f"{path}: INTEHEAD: not found; expected an INIT file")
    _check_head(p, heads[0].read("i"), grid)
    props: dict = {}
    for rec in records:
        if rec.keyword in _NOT_CELL or rec.length not in (grid.ncells, grid.nactive):
            continue
        if rec.type not in ("REAL", "DOUB", "INTE"):
            continue
        arr = _to_cells(rec.read(), grid, mask)
        if arr is not None:
            props[rec.keyword] = arr
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
        if not self.path.exists():
            raise InputError(f"{path}: no such file")
        check_file(self.path, "an ECLIPSE UNRST file")
        self.grid = grid
        self.dims = grid.dims
        want = None if keywords is None else {str(k).upper() for k in keywords}
        self.dates: list[str] = []
        self.seqnum: list[int] = []
        self.offsets: list[dict] = []
        self.records: list[dict[str, Record]] = []
        seqs: list[list[str]] = []  # the keywords of each step's records, in file order
        cells: list[set] = []  # the cell arrays of each step (any keyword)
        sizes = (grid.ncells, grid.nactive)
        damage = None
        try:
            for rec in scan(self.path):  # headers checked; stops at the first damaged record
                kw = rec.keyword
                if kw == "SEQNUM":
                    seq = rec.read("i")
                    if seq.size < 1:
                        raise RecordError(f"{path}: SEQNUM: expected 1 integer, got 0",
                                          rec.start, "SEQNUM")
                    self.seqnum.append(int(seq[0]))
                    self.dates.append("")
                    self.offsets.append({})
                    self.records.append({})
                    seqs.append([])
                    cells.append(set())
                    continue
                if not seqs:
                    continue
                seqs[-1].append(kw)
                if kw == "INTEHEAD":
                    head = rec.read("i")
                    _check_head(self.path, head, grid, _INTEHEAD_DATE)
                    d, m, y = (int(v) for v in head[64:67])
                    self.dates[-1] = f"{y:04d}-{m:02d}-{d:02d}" if y > 0 else ""
                elif (kw not in _NOT_CELL and rec.length in sizes
                      and rec.type in ("REAL", "DOUB", "INTE")):
                    cells[-1].add(kw)
                    if want is None or kw in want:
                        self.offsets[-1][kw] = rec.start
                        self.records[-1][kw] = rec
        except RecordError as err:
            damage = err
        self._keep_complete(damage, seqs, cells)
        found: dict[str, None] = {kw: None for step in self.offsets for kw in step}
        self.keywords = list(found)
        if want:
            missing = sorted(want - set(found))
            if missing:
                raise InputError(f"{path}: {', '.join(missing)}: not in any report step; the "
                                 f"file has {', '.join(self.keywords) or 'no cell arrays'}")

    def _keep_complete(self, damage: RecordError | None, seqs: list[list[str]],
                       cells: list[set]) -> None:
        """Drop the last report step when it is incomplete; warn when anything was lost.

        The last step read is incomplete when the damage lies inside one of its records (or
        right after one of its cell arrays, whose count is then suspect), when its records are
        a proper prefix of the step before (the file ends at a record boundary), when it opens
        STARTSOL without ENDSOL, or when it holds no cell array.  No complete step is an error.
        """
        note, bad = "", False
        if seqs:
            last = seqs[-1]
            prev = seqs[-2] if len(seqs) > 1 else None
            if damage is not None and (damage.keyword not in ("", "SEQNUM") or (
                    not damage.keyword and damage.after in cells[-1])):
                bad = True
            elif prev is not None and len(last) < len(prev) and prev[:len(last)] == last:
                lacks = prev[len(last):]
                bad, note = True, (f"it lacks {', '.join(lacks[:3])}"
                                   f"{' ...' if len(lacks) > 3 else ''} that step "
                                   f"{len(seqs) - 2} has")
            elif "STARTSOL" in last and "ENDSOL" not in last[last.index("STARTSOL"):]:
                bad, note = True, "STARTSOL without ENDSOL"
            elif not cells[-1]:
                bad, note = True, "no cell array"
        if not bad and damage is None:
            if not self.offsets:
                raise InputError(f"{self.path}: SEQNUM: no report steps found; expected a "
                                 "unified restart file")
            return
        if not seqs:
            raise damage or InputError(f"{self.path}: SEQNUM: no report steps found")
        if damage is None:
            cause = f"the file ends after {seqs[-1][-1] if seqs[-1] else 'SEQNUM'}"
        elif damage.truncated and damage.keyword:
            cause = f"the file ends inside {damage.keyword}"
        elif damage.truncated:
            cause = f"the file ends inside a record header after {damage.after}"
        else:
            cause = _without(damage, self.path)
        why = f"{note}; {cause}" if note else cause
        if bad:
            k = len(seqs) - 1
            label = f"report step {k} (SEQNUM {self.seqnum[k]})"
            for lst in (self.seqnum, self.offsets, self.records, self.dates):
                del lst[k:]
        else:  # the damage starts a step that was never read
            k = len(seqs)
            label = f"report step {k}"
        if k == 0:
            raise InputError(f"{self.path}: {label} is incomplete ({why}): no complete report "
                             "step (a killed run?)")
        warnings.warn(f"{self.path}: {label} is incomplete ({why}); read the {k} complete "
                      f"report step{'s' if k > 1 else ''} before it (a killed run?)",
                      stacklevel=3)

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
        kw = str(self.check(k, keyword))
        try:
            arr = self.records[k][kw].read()
        except RecordError as err:
            raise RecordError(f"{err} (report step {k})", err.offset, err.keyword,
                              err.after) from None
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


def _without(err: InputError, path) -> str:
    """The message of ``err`` without its leading ``path: ``."""
    text, head = str(err), f"{path}: "
    return text[len(head):] if text.startswith(head) else text


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
            if c.exists():   # a FIFO or a folder under that name: one line, not a hang
                return check_file(c, f"an ECLIPSE {e.lstrip('.').upper()} file")
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
            grid.check_steps()
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
