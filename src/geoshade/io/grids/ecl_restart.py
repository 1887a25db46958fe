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
they are mapped to all cells here: floats get NaN, integers 0 in inactive cells.  ECLIPSE's
undefined value (-1e20, :data:`UNDEFINED`) in a float array is no value: NaN.

- **local grid refinements**: a report step's ``LGR`` … ``ENDLGR`` sections (after the global
  ``ENDSOL``; ``LGRNAMES`` lists them) hold each LGR's own ``INTEHEAD`` and cell arrays.  They
  are indexed per LGR (:meth:`UnrstIndex.view` ``(lgr=NAME)``), never read as the global grid's;
  an LGR the grid does not know is skipped.
- **dual porosity/permeability**: a cell array holds the matrix's active cells, then the
  fracture's (:class:`CellMap`); ``view(medium="fracture")`` maps the second part.
- **time of day**: INTEHEAD items 207, 208 and 411 (hour, minute, microseconds; OPM's
  ``IHOURZ IMINTS ISECND``) are kept: when any step has a time of day, every step's date is
  ``YYYY-MM-DD HH:MM`` (``:SS`` when seconds are there), so hourly steps are told apart.
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
#: INTEHEAD indices of a report step's time of day: hour, minute, seconds in microseconds
INTEHEAD_HOUR, INTEHEAD_MINUTE, INTEHEAD_USEC = 206, 207, 410
#: ECLIPSE's undefined value is -1e20 (written as float32: -1.00000002e20); a float cell value
#: whose magnitude reaches this is no value (NaN)
UNDEFINED = 0.99e20
#: records that open and close a local grid's section in INIT and restart files
LGR_OPEN, LGR_CLOSE = "LGR", ("ENDLGR", "LGRSGONE")


def step_time(head) -> tuple[str, tuple[int, int, int]]:
    """``("YYYY-MM-DD", (hour, minute, microseconds))`` of a restart INTEHEAD ("" for the date
    when the year is not positive; zeros where the header is too short).

    Examples
    --------
    >>> head = np.zeros(411, np.int32); head[64:67] = (5, 3, 2015); head[206:208] = (6, 30)
    >>> step_time(head)
    ('2015-03-05', (6, 30, 0))
    """
    h = np.asarray(head)
    date = ""
    if h.size >= INTEHEAD_DATE:
        d, m, y = (int(v) for v in h[64:67])
        date = f"{y:04d}-{m:02d}-{d:02d}" if y > 0 else ""
    t = tuple(int(h[i]) if h.size > i else 0
              for i in (INTEHEAD_HOUR, INTEHEAD_MINUTE, INTEHEAD_USEC))
    return date, (t[0], t[1], t[2])


def step_labels(dates: Sequence[str], times: Sequence[tuple[int, int, int]]) -> list[str]:
    """Each step's date, with ``HH:MM`` (``:SS``) on every dated step when any step has a time
    of day (ECLIPSE restarts of hourly steps), else the dates as they are.

    Examples
    --------
    >>> step_labels(["2015-01-01"] * 2, [(0, 0, 0), (1, 0, 0)])
    ['2015-01-01 00:00', '2015-01-01 01:00']
    >>> step_labels(["2015-01-01", "2015-02-01"], [(0, 0, 0), (0, 0, 0)])
    ['2015-01-01', '2015-02-01']
    """
    if not any(any(t) for t in times):
        return list(dates)
    seconds = any(t[2] for t in times)
    out = []
    for d, (hh, mm, us) in zip(dates, times, strict=True):
        clock = f"{hh:02d}:{mm:02d}" + (f":{us // 1_000_000:02d}" if seconds else "")
        out.append(f"{d} {clock}" if d else d)
    return out


def head_sizes(grid) -> list[tuple[tuple[int, int, int], int]]:
    """The (NX, NY, NZ) and active-cell counts an INTEHEAD of ``grid``'s files may carry: the
    grid's own; for a dual-porosity grid also the doubled NZ (DIMENS of a ``DUALPORO`` deck)
    and the active cells of both media."""
    dims, nact = tuple(grid.dims), int(grid.nactive)
    media = getattr(grid, "dual_media", None) or {}
    if not media:
        return [(dims, nact)]
    both = sum(int(np.count_nonzero(np.asarray(m.actnum))) for m in media.values())
    nx, ny, nz = dims
    return [(d, a) for d in (dims, (nx, ny, 2 * nz)) for a in dict.fromkeys((nact, both))]


def check_head(path, head, grid, need: int = INTEHEAD_DIMS) -> None:
    """INTEHEAD's grid size and active cell count against the grid's (one line if not)."""
    if head.size < need:
        raise InputError(f"{path}: INTEHEAD: expected at least {need} integers (ECLIPSE writes "
                         f"411), got {head.size}")
    nx, ny, nz = (int(v) for v in head[8:11])
    nact = int(head[11])
    if ((nx, ny, nz), nact) not in head_sizes(grid):
        raise InputError(f"{path}: INTEHEAD: the file is for a {nx}×{ny}×{nz} grid with {nact} "
                         f"active cells; expected {'×'.join(map(str, grid.dims))} with "
                         f"{grid.nactive} (the EGRID's)")


def _no_undefined(a: np.ndarray) -> np.ndarray:
    """A float array with ECLIPSE's undefined value (±1e20 and beyond) as NaN (a copy only
    where there is one)."""
    if a.dtype.kind != "f" or not a.size:
        return a
    with np.errstate(invalid="ignore"):
        bad = np.abs(a) >= UNDEFINED
    if not bad.any():
        return a
    out = np.array(a, copy=True)
    out[bad] = np.nan
    return out


def to_cells(arr: np.ndarray, grid: CornerPointGrid, mask: np.ndarray) -> np.ndarray | None:
    """An active-cell (or all-cell) array -> (nx, ny, nz) F-order; None if it is neither.
    Floats: NaN in inactive cells and where the file holds ECLIPSE's undefined value (-1e20).

    Examples
    --------
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1]],
    ...                   [[1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]]], float)
    >>> zc = np.zeros((2, 2, 4), np.float32); zc[..., 1:3] = 1; zc[..., 3] = 2
    >>> g = CornerPointGrid(coord, zc, actnum=np.array([0, 1]).reshape(1, 1, 2))
    >>> to_cells(np.float32([0.3]), g, g.active.ravel(order="F")).ravel().tolist()
    [nan, 0.30000001192092896]
    >>> to_cells(np.float32([-1e20, 2]), g, None).ravel().tolist()
    [nan, 2.0]
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
    a = _no_undefined(a)
    if a.size == grid.ncells:
        return a.astype(dt).reshape(grid.dims, order="F")
    full = np.full(grid.ncells, np.nan if a.dtype.kind == "f" else 0, dt)
    full[mask] = a
    return full.reshape(grid.dims, order="F")


class CellMap:
    """How an INIT or restart cell array maps to a grid's cells.

    One medium: the array holds every cell, or the active cells in file order.  A dual-porosity
    or dual-permeability grid (``grid.dual_media``): every cell of the matrix then of the
    fracture (2·ncells values, e.g. PORV), or the matrix's active cells then the fracture's.

    Parameters
    ----------
    grid : CornerPointGrid (or anything with ``dims``, ``ncells``, ``nactive``; ``active``
        and ``dual_media`` are read when an array is mapped)

    Examples
    --------
    >>> from geoshade.models.grid import Medium
    >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1, 2)], float)
    >>> zc = np.repeat([[[0.0, 1.0]]], 4, 0).repeat(2, 1)
    >>> m, f = np.array([1, 1], np.uint8), np.array([0, 1], np.uint8)
    >>> g = CornerPointGrid(coord, zc, actnum=m.reshape(2, 1, 1), medium="matrix",
    ...     dual_media={"matrix": Medium("matrix", m.reshape(2, 1, 1)),
    ...                 "fracture": Medium("fracture", f.reshape(2, 1, 1))})
    >>> cm = CellMap(g)
    >>> sorted(cm.sizes), cm.cells(np.float32([1, 2, 3]), "fracture").ravel().tolist()
    ([3, 4], [nan, 3.0])
    """

    def __init__(self, grid):
        self.grid = grid
        media = getattr(grid, "dual_media", None) or {}
        self.media = tuple(media) or ("",)
        if media:
            counts = [int(np.count_nonzero(np.asarray(m.actnum))) for m in media.values()]
            self.counts = dict(zip(self.media, counts, strict=True))
            self.sizes = {len(self.media) * grid.ncells, sum(counts)}
        else:
            self.counts = {"": int(grid.nactive)}
            self.sizes = {int(grid.ncells), int(grid.nactive)}
        self.sizes.discard(0)

    def _mask(self, medium: str) -> np.ndarray:
        media = getattr(self.grid, "dual_media", None) or {}
        act = media[medium].actnum if medium else self.grid.actnum
        return np.asarray(act).reshape(-1, order="F") != 0

    def part(self, a: np.ndarray, medium: str) -> tuple[np.ndarray, bool]:
        """(the values of ``medium``, whether they are every cell's) of a file array."""
        medium = self._medium(medium)
        n, q = int(self.grid.ncells), self.media.index(medium)
        if a.size == len(self.media) * n:
            return a[q * n:(q + 1) * n], True
        start = sum(self.counts[m] for m in self.media[:q])
        return a[start:start + self.counts[medium]], False

    def _medium(self, medium: str | None) -> str:
        if medium is None or (medium == "" and self.media != ("",)):
            return self.media[0]
        if medium not in self.media:
            raise InputError(f"{self.grid.name}: medium {medium!r}: expected one of "
                             f"{', '.join(m or 'the one medium' for m in self.media)}")
        return medium

    def cells(self, arr: np.ndarray, medium: str | None = None) -> np.ndarray | None:
        """The (nx, ny, nz) F-order cells of ``medium`` (default: the first) of a file array;
        None when its length fits no layout of this grid."""
        a = np.asarray(arr)
        if a.dtype.kind not in "fi" or a.size not in self.sizes:
            return None
        vals, every = self.part(a, str(self._medium(medium)))
        dt = np.float32 if a.dtype.kind == "f" and a.dtype.itemsize <= 4 else \
            (np.float64 if a.dtype.kind == "f" else np.int32)
        g = self.grid
        check_memory(g.name, f"a cell array ({g.ncells} values)", g.ncells * np.dtype(dt).itemsize)
        vals = _no_undefined(vals)
        if every:
            return vals.astype(dt).reshape(g.dims, order="F")
        full = np.full(g.ncells, np.nan if a.dtype.kind == "f" else 0, dt)
        full[self._mask(str(self._medium(medium)))] = vals
        return full.reshape(g.dims, order="F")


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
    lgr_records : list of dict    per step, LGR name -> keyword -> record of that LGR's section
                             (the LGRs of ``grid.refinements`` only)
    lgr_names : list of list      per step, the LGRs its ``LGRNAMES`` (or sections) name
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
        self.cellmap = CellMap(grid)
        self.want = None if keywords is None else {str(k).upper() for k in keywords}
        #: the local grids whose sections are indexed: upper-case name -> its grid
        self.sub = {r.name.upper(): r.grid for r in getattr(grid, "refinements", None) or []}
        self._sub_maps: dict[str, CellMap] = {}
        self.files: list[Path] = []
        self.dates: list[str] = []
        self._times: list[tuple[int, int, int]] = []
        self.seqnum: list[int] = []
        self.offsets: list[dict] = []
        self.records: list[dict[str, Record]] = []
        self.step_records: list[dict[str, Record]] = []
        self.lgr_records: list[dict[str, dict[str, Record]]] = []
        self.lgr_names: list[list[str]] = []
        self._seqs: list[list[str]] = []  # the keywords of each step's records, in file order
        self._cells: list[set] = []  # the cell arrays of each step (any keyword)
        if self.unified:
            self._keep_complete(self._index(files[0], None), files[0], last=True)
        else:
            for n, f in enumerate(files):
                damage = self._index(f, report_number(f))
                self._keep_complete(damage, f, last=n == len(files) - 1)
        del self._seqs, self._cells
        self.dates = step_labels(self.dates, self._times)
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
        self._times.append((0, 0, 0))
        self.offsets.append({})
        self.records.append({})
        self.step_records.append({})
        self.lgr_records.append({})
        self.lgr_names.append([])
        self._seqs.append([])
        self._cells.append(set())

    def _drop(self, k: int) -> None:
        """Forget report steps ``k`` and after."""
        del self.files[k:], self.seqnum[k:], self.dates[k:], self.offsets[k:], self._times[k:]
        del self.records[k:], self.step_records[k:], self._seqs[k:], self._cells[k:]
        del self.lgr_records[k:], self.lgr_names[k:]

    def _sub_map(self, name: str) -> CellMap:
        if name not in self._sub_maps:
            self._sub_maps[name] = CellMap(self.sub[name])
        return self._sub_maps[name]

    def _lgr_record(self, path: Path, section: str, rec: Record) -> None:
        """A record of local grid ``section``'s part of the step: its INTEHEAD is checked
        against the LGR's grid (never the global one), its cell arrays indexed."""
        kw = rec.keyword
        if section not in self.sub:
            return  # an LGR the EGRID does not define (or a grid without its LGRs): skipped
        sub = self.sub[section]
        if kw == "INTEHEAD":
            check_head(f"{path} (LGR {section})", rec.read("i"), sub, INTEHEAD_DIMS)
        elif (kw not in NOT_CELL and rec.length in self._sub_map(section).sizes
              and rec.type in ("REAL", "DOUB", "INTE")
              and (self.want is None or kw in self.want)):
            self.lgr_records[-1].setdefault(section, {}).setdefault(kw, rec)

    def _index(self, path: Path, report: int | None) -> RecordError | None:
        """Index the records of one file; the damage that stopped the walk, or None."""
        sizes = self.cellmap.sizes
        if report is not None:  # non-unified: the file is one report step
            self._start(path, report)
        section = ""  # "" the global grid's records, else the LGR whose section this is
        try:
            for rec in scan(path):  # headers checked; stops at the first damaged record
                kw = rec.keyword
                if kw == "SEQNUM":
                    section = ""
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
                if kw == LGR_OPEN:
                    name = rec.read("S")
                    section = bytes(name[0]).decode(errors="replace").strip().upper() \
                        if len(name) else "?"
                    self._seqs[-1].append(f"LGR {section}")
                    if section not in self.lgr_names[-1]:
                        self.lgr_names[-1].append(section)
                    continue
                if kw in LGR_CLOSE:
                    self._seqs[-1].append(f"{kw} {section}")
                    section = ""
                    continue
                if section:
                    self._seqs[-1].append(f"{kw} {section}")
                    self._lgr_record(path, section, rec)
                    continue
                self._seqs[-1].append(kw)
                self.step_records[-1].setdefault(kw, rec)
                if kw == "LGRNAMES":
                    self.lgr_names[-1] = [bytes(v).decode(errors="replace").strip().upper()
                                          for v in rec.read("S")]
                elif kw == "INTEHEAD":
                    head = rec.read("i")
                    check_head(path, head, self.grid, INTEHEAD_DATE)
                    self.dates[-1], self._times[-1] = step_time(head)
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

    def view(self, lgr: str | None = None, medium: str | None = None) -> StepView:
        """The steps of one part of the case: the global grid (``lgr`` None) or local grid
        ``lgr``, in ``medium`` ("matrix", "fracture"; None: the first) of a dual grid."""
        return StepView(self, lgr, medium)

    def cached(self, k: int, keyword: str, lgr: str | None = None,
               medium: str | None = None) -> np.ndarray:
        """:meth:`__call__` keeping the last :attr:`cache_size` arrays, and no more than
        :attr:`cache_bytes` of them: a 1e8-cell step (400 MB) is read again when asked again
        rather than four of them held."""
        key: tuple = (int(k), str(keyword).upper())
        if lgr or medium:
            key += ((lgr or "").upper(), medium or "")
        cache = self.__dict__.setdefault("_cache", {})
        if key in cache:
            return cache[key]
        arr = self(int(k), key[1], lgr=lgr, medium=medium)
        if arr.nbytes <= self.cache_bytes:
            while cache and (len(cache) >= self.cache_size or sum(
                    a.nbytes for a in cache.values()) + arr.nbytes > self.cache_bytes):
                cache.pop(next(iter(cache)))
            cache[key] = arr
        return arr

    def part_records(self, lgr: str | None = None) -> list[dict[str, Record]]:
        """Per step, keyword -> record of the global grid (``lgr`` None) or of local grid
        ``lgr`` (an empty dict in a step without its section)."""
        if not lgr:
            return self.records
        name = lgr.upper()
        return [step.get(name, {}) for step in self.lgr_records]

    def check(self, k: int, keyword: str | None = None, lgr: str | None = None) -> str | None:
        """``keyword`` in upper case if step ``k`` holds it (one line if not)."""
        n = len(self.offsets)
        if not isinstance(k, int | np.integer) or not 0 <= k < n:
            whose = "file" if self.unified else "case"
            raise InputError(f"{self.label}: step {k} does not exist; the {whose} has {n} "
                             f"report steps (0-{n - 1})")
        if keyword is None:
            return None
        kw = str(keyword).upper()
        recs = self.part_records(lgr)[k]
        if kw not in recs:
            have = ", ".join(recs) or "no cell arrays"
            where = f" of LGR {lgr.upper()}" if lgr else ""
            raise InputError(f"{self.files[k]}: {kw} is not in report step {k}{where}; it has "
                             f"{have}")
        return kw

    def __call__(self, k: int, keyword: str, lgr: str | None = None,
                 medium: str | None = None) -> np.ndarray:
        """The (nx, ny, nz) array of ``keyword`` at report step ``k`` (NaN in inactive cells) of
        the global grid or local grid ``lgr``, in ``medium`` of a dual grid."""
        kw = str(self.check(k, keyword, lgr))
        rec = self.part_records(lgr)[k][kw]
        try:
            arr = rec.read()
        except RecordError as err:
            raise RecordError(f"{err} (report step {k})", err.offset, err.keyword,
                              err.after) from None
        cm = self._sub_map(lgr.upper()) if lgr else self.cellmap
        out = cm.cells(arr, medium)
        if out is None:  # pragma: no cover - sizes were checked by the index
            raise InputError(f"{self.files[k]}: {kw} (step {k}): unexpected length {arr.size}")
        return out

    def step(self, k: int, lgr: str | None = None, medium: str | None = None) -> dict:
        """All indexed keywords of step ``k``."""
        self.check(k)
        return {kw: self(k, kw, lgr, medium) for kw in self.part_records(lgr)[k]}


class StepView:
    """The report steps of one part of a case (the global grid or an LGR; one medium of a dual
    grid), read through its :class:`UnrstIndex`: ``view(k, keyword)`` -> (nx, ny, nz) array.

    ``offsets`` (per step, keyword -> byte offset), ``keywords``, ``dates``, ``seqnum``,
    ``files``, ``path``, ``label``, ``unified`` as the index's.
    """

    def __init__(self, index: UnrstIndex, lgr: str | None = None, medium: str | None = None):
        self.index, self.lgr, self.medium = index, (lgr or None), medium
        self.grid = index.sub[lgr.upper()] if lgr else index.grid
        recs = index.part_records(self.lgr)
        self.records = recs
        self.offsets = [{kw: r.start for kw, r in step.items()} for step in recs]
        self.keywords = list(dict.fromkeys(kw for step in recs for kw in step))

    def __getattr__(self, name: str):
        if name in ("dates", "seqnum", "files", "path", "label", "unified"):
            return getattr(self.index, name)
        raise AttributeError(name)

    def __len__(self) -> int:
        return len(self.index)

    def __call__(self, k: int, keyword: str) -> np.ndarray:
        return self.index(k, keyword, self.lgr, self.medium)

    def cached(self, k: int, keyword: str) -> np.ndarray:
        return self.index.cached(k, keyword, self.lgr, self.medium)

    def check(self, k: int, keyword: str | None = None) -> str | None:
        return self.index.check(k, keyword, self.lgr)

    def step(self, k: int) -> dict:
        return self.index.step(k, self.lgr, self.medium)


class LazyStep(Mapping):
    """``grid.steps[k]`` of a large restart: keyword -> (nx, ny, nz) array, read on access.

    ``index`` is an :class:`UnrstIndex` (the global grid) or a :class:`StepView`."""

    def __init__(self, index: UnrstIndex | StepView, k: int):
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


def read_steps(index: UnrstIndex | StepView, progress: Progress | None) -> list[dict]:
    """Every report step of ``index`` as arrays, reporting ``progress(k + 1, n)``."""
    report, n, steps = resolve(progress), len(index), []
    for k in range(n):  # report steps
        steps.append(index.step(k))
        report(k + 1, n)
    return steps


def restart_bytes(index: UnrstIndex | StepView) -> int:
    """Bytes the indexed cell arrays of every step take in memory (4 a value, all cells)."""
    return sum(len(o) for o in index.offsets) * index.grid.ncells * 4


def lazy_steps(index: UnrstIndex | StepView) -> Sequence[LazyStep]:
    """One :class:`LazyStep` a report step."""
    return [LazyStep(index, k) for k in range(len(index))]
