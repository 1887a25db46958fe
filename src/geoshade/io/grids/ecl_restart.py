"""Report steps of an ECLIPSE/OPM case: unified (``CASE.UNRST``, ``CASE.FUNRST``) or
non-unified (``CASE.X0001`` ..., ``CASE.F0001`` ...) restart files, indexed and read lazily.

:class:`UnrstIndex` walks the record headers (:func:`geoshade.io.grids.ecl_records.scan`: binary or
formatted, every header checked) and keeps, per report step, where each cell array lies; an array
is read from its byte offset when it is asked for, so a restart is never read whole.

- **unified**: one file, a report step from each ``SEQNUM`` to the next;
- **non-unified**: one file a report step, its report number from the suffix (``X0036``: 36);
  a ``SEQNUM`` in the file (ECLIPSE and OPM write none there) must agree with it.

Both give the same steps (tested on the Reek run split into X files).  A truncated last step (a
killed run) is dropped with one warning; a damaged non-unified file before the last is an error
naming the file.  INIT and restart cell arrays hold the **active** cells only (in file order);
they are mapped to all cells here: floats get NaN, integers 0 in inactive cells.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import RESTART_SUFFIX, Record, RecordError, scan
from geoshade.io.grids.grid_checks import check_memory
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid
from geoshade.progress import Progress, resolve

#: INIT/UNRST arrays that are not cell properties even when their length matches
NOT_CELL = frozenset({"INTEHEAD", "LOGIHEAD", "DOUBHEAD", "TABDIMS", "TAB", "SEQNUM",
                      "TRANNNC", "ICON", "SCON", "XCON", "IWEL", "SWEL", "XWEL", "ZWEL",
                      "IGRP", "SGRP", "XGRP", "ZGRP", "ISEG", "RSEG", "IUAD", "IUAP"})
#: INTEHEAD values needed: grid size and active cells at 8-11, the date at 64-66
INTEHEAD_DIMS, INTEHEAD_DATE = 12, 67


def check_head(path, head, grid: CornerPointGrid, need: int = INTEHEAD_DIMS) -> None:
    """INTEHEAD's grid size and active cell count against the grid's (one line if not)."""
    if head.size < need:
        raise InputError(f"{path}: INTEHEAD: expected at least {need} integers (ECLIPSE writes "
                         f"411), got {head.size}")
    nx, ny, nz = (int(v) for v in head[8:11])
    nact = int(head[11])
    if (nx, ny, nz) != grid.dims or nact != grid.nactive:
        raise InputError(f"{path}: INTEHEAD: the file is for a {nx}×{ny}×{nz} grid with {nact} "
                         f"active cells; expected {'×'.join(map(str, grid.dims))} with "
                         f"{grid.nactive} (the EGRID's)")


def to_cells(arr: np.ndarray, grid: CornerPointGrid, mask: np.ndarray) -> np.ndarray | None:
    """An active-cell (or all-cell) array -> (nx, ny, nz) F-order; None if it is neither.

    Examples
    --------
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> zc = np.zeros((2, 2, 4), np.float32); zc[..., 1:3] = 1; zc[..., 3] = 2
    >>> g = CornerPointGrid(coord, zc, actnum=np.array([0, 1]).reshape(1, 1, 2))
    >>> to_cells(np.float32([0.3]), g, g.active.ravel(order="F")).ravel().tolist()
    [nan, 0.30000001192092896]
    """
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


def report_number(path: Path) -> int:
    """The report number in a non-unified restart file's suffix (``CASE.X0036`` -> 36).

    Examples
    --------
    >>> report_number(Path("CASE.X0036")), report_number(Path("case.f0001"))
    (36, 1)
    """
    m = RESTART_SUFFIX.fullmatch(path.suffix)
    if m is None:
        raise InputError(f"{path}: not a non-unified restart file name; expected CASE.X0001 "
                         "(binary) or CASE.F0001 (formatted)")
    return int(m[2])


class UnrstIndex:
    """Where each report step's cell arrays lie in a case's restart files; ``index(k, keyword)``
    reads one.

    Parameters
    ----------
    path : str or Path, or a sequence of them
        One unified restart file (``.UNRST``, ``.FUNRST``), or the non-unified files of a case
        (``.X0001`` ..., ``.F0001`` ...) in report order.
    grid : CornerPointGrid
        The case's grid (its ACTNUM maps active-cell arrays to all cells).
    keywords : list of str, optional
        Index only these cell keywords (default: every cell array).

    Attributes
    ----------
    path : Path              the unified file, or the first non-unified one
    unified : bool
    files : list of Path     the file of each report step
    dates : list of str      ISO date of each report step (from INTEHEAD)
    seqnum : list of int     the report number of each step (SEQNUM, or the file's suffix)
    keywords : list of str   cell keywords found (SWAT, SGAS, PRESSURE, ...)
    offsets : list of dict   keyword -> byte offset of its record, per step
    step_records : list of dict   every record of each step by keyword (the first of each;
                             IWEL, ICON, ZWEL ... for the wells), nothing read
    """

    cache_size = 4
    cache_bytes = 256 << 20

    def __init__(self, path, grid: CornerPointGrid, keywords=None):
        self.unified = isinstance(path, str | Path)
        files = [Path(path)] if self.unified else [Path(f) for f in path]
        if not files:
            raise InputError("restart: no files given")
        for f in files:
            if not f.exists():
                raise InputError(f"{f}: no such file")
            check_file(f, f"an ECLIPSE {'unified ' if self.unified else ''}restart file")
        self.path = files[0]
        self.grid = grid
        self.dims = grid.dims
        self.want = None if keywords is None else {str(k).upper() for k in keywords}
        self.files: list[Path] = []
        self.dates: list[str] = []
        self.seqnum: list[int] = []
        self.offsets: list[dict] = []
        self.records: list[dict[str, Record]] = []
        self.step_records: list[dict[str, Record]] = []
        self._seqs: list[list[str]] = []  # the keywords of each step's records, in file order
        self._cells: list[set] = []  # the cell arrays of each step (any keyword)
        if self.unified:
            self._keep_complete(self._index(files[0], None), files[0], last=True)
        else:
            for n, f in enumerate(files):
                damage = self._index(f, report_number(f))
                self._keep_complete(damage, f, last=n == len(files) - 1)
        del self._seqs, self._cells
        found: dict[str, None] = {kw: None for step in self.offsets for kw in step}
        self.keywords = list(found)
        if self.want:
            missing = sorted(self.want - set(found))
            if missing:
                raise InputError(f"{self.label}: {', '.join(missing)}: not in any report step; "
                                 f"the file has {', '.join(self.keywords) or 'no cell arrays'}")

    @property
    def label(self) -> str:
        """The file, or the first and last of the non-unified files, for messages."""
        if self.unified or len(self.files) < 2:
            return str(self.path)
        return f"{self.files[0]} … {self.files[-1].name}"

    def _start(self, path: Path, seqnum: int) -> None:
        """Open a report step."""
        self.files.append(path)
        self.seqnum.append(seqnum)
        self.dates.append("")
        self.offsets.append({})
        self.records.append({})
        self.step_records.append({})
        self._seqs.append([])
        self._cells.append(set())

    def _drop(self, k: int) -> None:
        """Forget report steps ``k`` and after."""
        del self.files[k:], self.seqnum[k:], self.dates[k:], self.offsets[k:]
        del self.records[k:], self.step_records[k:], self._seqs[k:], self._cells[k:]

    def _index(self, path: Path, report: int | None) -> RecordError | None:
        """Index the records of one file; the damage that stopped the walk, or None."""
        sizes = (self.grid.ncells, self.grid.nactive)
        if report is not None:  # non-unified: the file is one report step
            self._start(path, report)
        try:
            for rec in scan(path):  # headers checked; stops at the first damaged record
                kw = rec.keyword
                if kw == "SEQNUM":
                    seq = rec.read("i")
                    if seq.size < 1:
                        raise RecordError(f"{path}: SEQNUM: expected 1 integer, got 0",
                                          rec.start, "SEQNUM")
                    if report is None:
                        self._start(path, int(seq[0]))
                        continue
                    if int(seq[0]) != report or "SEQNUM" in self._seqs[-1]:
                        raise InputError(f"{path}: SEQNUM: report {int(seq[0])} in a file "
                                         f"named for report {report}; expected one report step "
                                         f"a file (a unified restart is named .UNRST)")
                if not self._seqs:
                    continue
                self._seqs[-1].append(kw)
                self.step_records[-1].setdefault(kw, rec)
                if kw == "INTEHEAD":
                    head = rec.read("i")
                    check_head(path, head, self.grid, INTEHEAD_DATE)
                    d, m, y = (int(v) for v in head[64:67])
                    self.dates[-1] = f"{y:04d}-{m:02d}-{d:02d}" if y > 0 else ""
                elif (kw not in NOT_CELL and rec.length in sizes
                      and rec.type in ("REAL", "DOUB", "INTE")):
                    self._cells[-1].add(kw)
                    if self.want is None or kw in self.want:
                        self.offsets[-1][kw] = rec.start
                        self.records[-1][kw] = rec
        except RecordError as err:
            return err
        return None

    def _keep_complete(self, damage: RecordError | None, path: Path, last: bool) -> None:
        """Drop the last report step when it is incomplete; warn when anything was lost.

        The last step read is incomplete when the damage lies inside one of its records (or
        right after one of its cell arrays, whose count is then suspect), when its records are
        a proper prefix of the step before (the file ends at a record boundary), when it opens
        STARTSOL without ENDSOL, or when it holds no cell array; any damage in a non-unified
        file.  Then: the case's last file loses that step with a warning (a killed run); an
        earlier non-unified file is an error naming it.  No complete step is an error.
        """
        seqs, cells = self._seqs, self._cells
        note, bad = "", False
        if seqs:
            steps = seqs[-1]
            prev = seqs[-2] if len(seqs) > 1 else None
            if damage is not None and (not self.unified or damage.keyword not in ("", "SEQNUM")
                                       or (not damage.keyword and damage.after in cells[-1])):
                bad = True
            elif prev is not None and len(steps) < len(prev) and prev[:len(steps)] == steps:
                lacks = prev[len(steps):]
                bad, note = True, (f"it lacks {', '.join(lacks[:3])}"
                                   f"{' ...' if len(lacks) > 3 else ''} that step "
                                   f"{len(seqs) - 2} has")
            elif "STARTSOL" in steps and "ENDSOL" not in steps[steps.index("STARTSOL"):]:
                bad, note = True, "STARTSOL without ENDSOL"
            elif not cells[-1]:
                bad, note = True, "no cell array"
        if not bad and damage is None:
            if not self.offsets:
                raise InputError(f"{path}: SEQNUM: no report steps found; expected a "
                                 "unified restart file")
            return
        if not seqs:
            raise damage or InputError(f"{path}: SEQNUM: no report steps found")
        if damage is None:
            cause = f"the file ends after {seqs[-1][-1] if seqs[-1] else 'its header'}"
        elif damage.truncated and damage.keyword:
            cause = f"the file ends inside {damage.keyword}"
        elif damage.truncated:
            cause = (f"the file ends inside a record header after {damage.after}"
                     if damage.after else "the file is empty")
        else:
            cause = _without(damage, path)
        why = f"{note}; {cause}" if note else cause
        k = len(seqs) - 1 if bad else len(seqs)
        label = (f"report step {k} (SEQNUM {self.seqnum[k]})" if self.unified and bad else
                 f"report step {k}" if self.unified else f"report step {k} ({path.name})")
        if not last:
            raise InputError(f"{path}: {label} is incomplete ({why}); a restart file of the "
                             "case is damaged")
        if bad:
            self._drop(k)
        if k == 0:
            raise InputError(f"{path}: {label} is incomplete ({why}): no complete report "
                             "step (a killed run?)")
        warnings.warn(f"{path}: {label} is incomplete ({why}); read the {k} complete "
                      f"report step{'s' if k > 1 else ''} before it (a killed run?)",
                      stacklevel=4)

    def __len__(self) -> int:
        return len(self.offsets)

    def cached(self, k: int, keyword: str) -> np.ndarray:
        """:meth:`__call__` keeping the last :attr:`cache_size` arrays, and no more than
        :attr:`cache_bytes` of them: a 1e8-cell step (400 MB) is read again when asked again
        rather than four of them held."""
        key = (int(k), str(keyword).upper())
        cache = self.__dict__.setdefault("_cache", {})
        if key in cache:
            return cache[key]
        arr = self(*key)
        if arr.nbytes <= self.cache_bytes:
            while cache and (len(cache) >= self.cache_size or sum(
                    a.nbytes for a in cache.values()) + arr.nbytes > self.cache_bytes):
                cache.pop(next(iter(cache)))
            cache[key] = arr
        return arr

    def check(self, k: int, keyword: str | None = None) -> str | None:
        """``keyword`` in upper case if step ``k`` holds it (one line if not)."""
        n = len(self.offsets)
        if not isinstance(k, int | np.integer) or not 0 <= k < n:
            whose = "file" if self.unified else "case"
            raise InputError(f"{self.label}: step {k} does not exist; the {whose} has {n} "
                             f"report steps (0-{n - 1})")
        if keyword is None:
            return None
        kw = str(keyword).upper()
        if kw not in self.offsets[k]:
            have = ", ".join(self.offsets[k]) or "no cell arrays"
            raise InputError(f"{self.files[k]}: {kw} is not in report step {k}; it has {have}")
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
        out = to_cells(arr, self.grid, mask)
        if out is None:  # pragma: no cover - sizes were checked by the index
            raise InputError(f"{self.files[k]}: {kw} (step {k}): unexpected length {arr.size}")
        return out

    def step(self, k: int) -> dict:
        """All indexed keywords of step ``k``."""
        self.check(k)
        return {kw: self(k, kw) for kw in self.offsets[k]}


class LazyStep(Mapping):
    """``grid.steps[k]`` of a large restart: keyword -> (nx, ny, nz) array, read on access."""

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
    """All report steps of a case's restart files, in report order.

    Parameters
    ----------
    path : str or Path, or a sequence of them
        A unified restart (``.UNRST``, ``.FUNRST``) or the non-unified files (``.X0001`` ...).
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

    Examples
    --------
    >>> import numpy as np, os, tempfile, resfo
    >>> from geoshade.models import CornerPointGrid
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> zc = np.zeros((2, 2, 2), np.float32); zc[..., 1] = 1
    >>> g = CornerPointGrid(coord, zc)
    >>> d = tempfile.mkdtemp()
    >>> for k in (1, 2):   # non-unified: one file a report step, no SEQNUM
    ...     head = np.zeros(411, np.int32); head[8:12] = (1, 1, 1, 1); head[64:67] = (1, k, 2001)
    ...     resfo.write(os.path.join(d, f"C.X{k:04d}"),
    ...                 [("INTEHEAD", head), ("SWAT    ", np.array([k / 10], np.float32))])
    >>> steps, dates = read_unrst([os.path.join(d, "C.X0001"), os.path.join(d, "C.X0002")], g)
    >>> dates, [round(float(s["SWAT"][0, 0, 0]), 6) for s in steps]
    (['2001-01-01', '2001-02-01'], [0.1, 0.2])
    """
    index = UnrstIndex(path, grid, keywords)
    return read_steps(index, progress), list(index.dates)


def _without(err: InputError, path) -> str:
    """The message of ``err`` without its leading ``path: ``."""
    text, head = str(err), f"{path}: "
    return text[len(head):] if text.startswith(head) else text


def read_steps(index: UnrstIndex, progress: Progress | None) -> list[dict]:
    """Every report step of ``index`` as arrays, reporting ``progress(k + 1, n)``."""
    report, n, steps = resolve(progress), len(index), []
    for k in range(n):  # report steps
        steps.append(index.step(k))
        report(k + 1, n)
    return steps


def restart_bytes(index: UnrstIndex) -> int:
    """Bytes the indexed cell arrays of every step take in memory (4 a value, all cells)."""
    return sum(len(o) for o in index.offsets) * index.grid.ncells * 4


def lazy_steps(index: UnrstIndex) -> Sequence[LazyStep]:
    """One :class:`LazyStep` a report step."""
    return [LazyStep(index, k) for k in range(len(index))]
