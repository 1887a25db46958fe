"""ECLIPSE / OPM Flow output: EGRID (geometry), INIT (static properties), restart files (report
steps), binary or formatted, read through :mod:`resfo` and :mod:`geoshade.io.grids.ecl_records`.

A case is opened from **any of its files** (:func:`load_case`, :func:`case_files`): the EGRID
or FEGRID (or the old GRID, :mod:`ecl_gridfile`), the INIT or FINIT, a unified restart (UNRST,
FUNRST), a non-unified one (``.X0001``, ``.F0001``) or a summary file; the others are found
beside it by the case name.  Formatted files read exactly as the binary ones.  A grid file
alone gives its geometry and a note (``meta["notes"]``) naming the files that would add
properties and report steps.  Local grid refinements (:mod:`lgr`) and dual-porosity or
dual-permeability media (:mod:`ecl_dual`) are read with the global grid.

INIT and restart files store cell arrays for the **active** cells only (in file order); they
are mapped to all cells here: floats get NaN, integers 0 in inactive cells.

Report steps are not read at once: :func:`load_case` puts an :class:`UnrstIndex` in
``grid.meta["unrst"]``.  It is a callable ``read_step(k, keyword) -> (nx, ny, nz) array`` that
seeks to the one array it needs; ``grid.meta["step_keywords"]`` lists the keywords.
``grid.steps`` works either way: for small restarts (up to ``eager_bytes``) it holds arrays, for
large ones :class:`LazyStep` mappings that read an array when it is indexed
(``grid.steps[k]["SWAT"]``; the last few are cached).  :func:`step_property` reads a step
property with one-line errors for a missing step or keyword.  Which restart files were used
(unified before non-unified, the format of the file given first) is in ``grid.meta["restart"]``.

Damaged files (:mod:`geoshade.io.grids.ecl_records` walks and checks every record header first): a
truncated or damaged EGRID or INIT is one error naming the file and the keyword; a truncated
restart (what a killed run leaves) gives its complete report steps and one warning naming the
first incomplete one; restart files present but unreadable are one error naming the file.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_gridfile import GRID_FILE_SUFFIXES, is_ecl_grid, read_ecl_grid
from geoshade.io.grids.ecl_records import RESTART_SUFFIX, scan
from geoshade.io.grids.ecl_restart import (
    LazyStep,
    UnrstIndex,
    lazy_steps,
    read_steps,
    read_unrst,
    report_number,
    restart_bytes,
)
from geoshade.io.grids.egrid import read_egrid
from geoshade.io.grids.lgr import (
    init_sections,
    refinement_init,
    refinement_steps,
    section_properties,
)
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid
from geoshade.progress import Progress

__all__ = ["CaseFiles", "LazyStep", "UnrstIndex", "case_files", "is_case_file", "load_case",
           "read_egrid", "read_init", "read_unrst", "step_property"]

#: load all report steps into ``grid.steps`` when they take at most this many bytes
EAGER_BYTES = 256 << 20
#: INTEHEAD item 3 (index 2) of INIT and restart files -> the case's unit system
UNIT_SYSTEMS = {1: "METRIC", 2: "FIELD", 3: "LAB", 4: "PVT-M"}
#: the suffixes of a case's files (upper case), by kind; ``F`` before a binary one: formatted
GRID_SUFFIXES = (".EGRID", ".FEGRID")
INIT_SUFFIXES = (".INIT", ".FINIT")
UNIFIED_SUFFIXES = (".UNRST", ".FUNRST")
SUMMARY_SUFFIXES = (".SMSPEC", ".UNSMRY", ".FSMSPEC", ".FUNSMRY")
CASE_SUFFIXES = GRID_SUFFIXES + INIT_SUFFIXES + UNIFIED_SUFFIXES + SUMMARY_SUFFIXES


def read_init(path, grid: CornerPointGrid) -> dict:
    """Static cell properties of an INIT or FINIT file (PORO, PERMX, NTG, FIPNUM, ...), on all
    cells; the unit system of INTEHEAD's item 3 goes in ``grid.meta["unit_system"]``.

    Arrays of the active cells are mapped to all cells (NaN / 0 in inactive cells); arrays of
    all cells (e.g. PORV) are kept as they are; ECLIPSE's undefined value (-1e20) is NaN.  Only
    the global grid's section is read: each local grid refinement's section gives its grid's
    properties (``grid.refinements[n].grid.properties``, set here); in a dual grid the
    properties returned are the shown medium's and every medium gets its own
    (``grid.dual_media[m].properties``, set here).

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
    records = list(scan(p))  # every header checked, to the end of the file, before any array
    main, lgrs = init_sections(records)
    if not any(r.keyword == "INTEHEAD" for r in records):
        raise InputError(f"{path}: INTEHEAD: not found; expected an INIT file")
    media = section_properties(p, main, grid)
    head = next(r for r in main if r.keyword == "INTEHEAD").read("i")
    if len(head) > 2 and int(head[2]) in UNIT_SYSTEMS:  # item 3: the case's unit system
        grid.meta["unit_system"] = UNIT_SYSTEMS[int(head[2])]
    for name, m in grid.dual_media.items():
        m.properties = media[name]
    refinement_init(p, lgrs, grid)
    return media[grid.medium] if grid.dual_media else media[""]


# --- the files of a case -----------------------------------------------------------------------
def is_case_file(path) -> bool:
    """Whether ``path``'s suffix names a file of an ECLIPSE/OPM case (EGRID, INIT, UNRST, X0001,
    their formatted forms, SMSPEC, UNSMRY), in any case.

    Examples
    --------
    >>> [is_case_file(f) for f in ("A.EGRID", "a.funrst", "A.X0036", "A.F0001", "A.grdecl")]
    [True, True, True, True, False]
    """
    suffix = Path(path).suffix
    return suffix.upper() in CASE_SUFFIXES or RESTART_SUFFIX.fullmatch(suffix) is not None


def _formatted_name(path: Path) -> bool:
    """Whether the name says formatted (``.FEGRID``, ``.FINIT``, ``.FUNRST``, ``.F0001``)."""
    m = RESTART_SUFFIX.fullmatch(path.suffix)
    if m:
        return m[1] in "Ff"
    return path.suffix.upper() in (".FEGRID", ".FINIT", ".FUNRST", ".FSMSPEC", ".FUNSMRY",
                                   ".FGRID")


def _find(folder: Path, stem: str, suffixes, what: str) -> Path | None:
    """The first of ``stem + suffix`` (upper, then lower case) in ``folder``, or None; a FIFO or
    a folder under that name is one line, not a hang."""
    for ext in suffixes:
        for e in (ext, ext.lower()):
            c = folder / (stem + e)
            if c.exists():
                return check_file(c, f"an ECLIPSE {what} file")
    return None


def _find_old_grid(folder: Path, stem: str, pref) -> Path | None:
    """The case's old GRID/FGRID file beside it (by content: a GRDECL text file may have the
    same suffix), or None."""
    for f in pref:
        for ext in (f".{f}GRID", f".{f}GRID".lower()):
            c = folder / (stem + ext)
            if c.is_file() and is_ecl_grid(c):
                return c
    return None


def _non_unified(folder: Path, stem: str) -> dict[str, list[Path]]:
    """The non-unified restart files of case ``stem``: ``{"X": [...], "F": [...]}`` in report
    order (one file a report number; the upper-case name first)."""
    pattern = re.compile(re.escape(stem) + r"\.([XxFf])(\d{4})")
    found: dict[str, dict[int, Path]] = {"X": {}, "F": {}}
    try:
        entries = sorted(e.name for e in os.scandir(folder))
    except OSError:
        return {"X": [], "F": []}
    for name in entries:
        m = pattern.fullmatch(name)
        if m:
            found[m[1].upper()].setdefault(int(m[2]), folder / name)
    return {k: [v[n] for n in sorted(v)] for k, v in found.items()}


def _span(files: list[Path]) -> str:
    return files[0].name if len(files) == 1 else \
        f"{files[0].name} … {files[-1].name} ({len(files)} files)"


@dataclass
class CaseFiles:
    """The files of one ECLIPSE/OPM case, as :func:`case_files` found them.

    grid:    Path                      the EGRID or FEGRID
    init:    Path or None              the INIT or FINIT
    restart: Path, list of Path, None  a unified restart, or the non-unified files in report
                                       order
    unused:  list of Path              restart files present but not used (the other kind or
                                       format)
    """

    grid: Path
    init: Path | None
    restart: Path | list[Path] | None
    unused: list[Path] = field(default_factory=list)

    def restart_meta(self) -> dict:
        """``grid.meta["restart"]``: kind, format, files, unused and a one-line summary."""
        if self.restart is None:
            return {}
        files = [self.restart] if isinstance(self.restart, Path) else list(self.restart)
        kind = "unified" if isinstance(self.restart, Path) else "non-unified"
        fmt = "formatted" if _formatted_name(files[0]) else "unformatted"
        summary = f"{_span(files)} ({kind}, {fmt})"
        if self.unused:
            summary += f"; not used: {_span(self.unused)}"
        return {"kind": kind, "format": fmt, "files": [str(f) for f in files],
                "unused": [str(f) for f in self.unused], "summary": summary}


def case_files(path) -> CaseFiles:
    """Find the files of the ECLIPSE/OPM case that ``path`` belongs to.

    ``path`` is any file of the case (EGRID, FEGRID, INIT, FINIT, UNRST, FUNRST, X0001, F0001,
    SMSPEC, UNSMRY); the others are looked for beside it under the same case name.  Files of
    the format the given file has come first (``CASE.FINIT`` opens ``CASE.FEGRID`` when both
    grids are there).  Restarts: the file given when it is one (a non-unified file brings all
    of its kind); else the unified restart, else the non-unified files; the rest are listed as
    ``unused``.

    Raises
    ------
    InputError
        No EGRID or FEGRID beside it (one line saying what was looked for where).

    Examples
    --------
    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> for name in ("C.EGRID", "C.INIT", "C.UNRST", "C.X0001", "C.X0002"):
    ...     open(os.path.join(d, name), "wb").close()
    >>> f = case_files(os.path.join(d, "C.X0002"))
    >>> f.grid.name, f.init.name, [p.name for p in f.restart], [p.name for p in f.unused]
    ('C.EGRID', 'C.INIT', ['C.X0001', 'C.X0002'], ['C.UNRST'])
    >>> case_files(os.path.join(d, "C.INIT")).restart_meta()["summary"]
    'C.UNRST (unified, unformatted); not used: C.X0001 … C.X0002 (2 files)'
    """
    p = Path(path)
    old_grid = p.suffix.upper() in GRID_FILE_SUFFIXES and p.is_file() and is_ecl_grid(p)
    if not is_case_file(p) and not old_grid:
        raise InputError(f"{path}: not a file of an ECLIPSE/OPM case; expected .EGRID, .INIT, "
                         ".UNRST, .X0001 or their formatted forms (.FEGRID ...)")
    stem, folder, suffix = p.name[: -len(p.suffix)], p.parent, p.suffix.upper()
    pref = ("F", "") if _formatted_name(p) else ("", "F")
    grids = [f".{f}EGRID" for f in pref]
    grid = p if suffix in GRID_SUFFIXES or old_grid else (
        _find(folder, stem, grids, "EGRID") or _find_old_grid(folder, stem, pref))
    if grid is None:
        raise InputError(f"{path}: no grid of case {stem} beside it (looked for "
                         f"{stem}{grids[0]}, {stem}{grids[1]} and {stem}.GRID in {folder}); an "
                         "ECLIPSE/OPM case is opened with its EGRID (or old GRID)")
    init = p if suffix in INIT_SUFFIXES else _find(folder, stem, [f".{f}INIT" for f in pref],
                                                   "INIT")
    unified = [u for u in (_find(folder, stem, [f".{f}UNRST"], "UNRST") for f in pref) if u]
    split = _non_unified(folder, stem)
    sets = [split[f or "X"] for f in pref if split[f or "X"]]
    restart: Path | list[Path] | None
    m = RESTART_SUFFIX.fullmatch(p.suffix)
    if suffix in UNIFIED_SUFFIXES:
        restart = p
    elif m:
        restart = split[m[1].upper()]
    else:
        restart = unified[0] if unified else (sets[0] if sets else None)
    unused = [u for u in unified if u != restart] + [f for s in sets if s != restart for f in s]
    return CaseFiles(grid, init, restart, unused)


def load_case(path, keywords=None, eager_bytes: int = EAGER_BYTES,
              progress: Progress | None = None) -> CornerPointGrid:
    """An ECLIPSE/OPM case: geometry, INIT properties and the restarts' report steps.

    Parameters
    ----------
    path : str or Path
        Any file of the case (see :func:`case_files`): ``CASE.EGRID`` or ``CASE.FEGRID``,
        ``CASE.INIT``, ``CASE.UNRST``, ``CASE.X0012``, ...; the grid must lie beside it, the
        INIT and restarts may.  A grid file alone gives the geometry, and a note
        (``meta["notes"]``) naming the files that would add properties and report steps.
        A non-unified restart file given itself (``CASE.X0012``) is the step shown by default
        (``meta["default_step"]``: its index).
    keywords : list of str, optional
        Restart keywords to index (default all cell arrays: SWAT, SGAS, PRESSURE, ...).
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
        ``meta["step_keywords"]``, ``meta["init"]``, ``meta["unrst_path"]`` (the unified file
        or the first non-unified one), ``meta["unrst_seqnum"]`` (report numbers),
        ``meta["restart"]`` (see :meth:`CaseFiles.restart_meta`), ``meta["notes"]``;
        ``refinements`` (local grids with their own properties and steps) and, for a
        dual-porosity/permeability case, ``dual_media`` (see
        :meth:`~geoshade.models.CornerPointGrid.select_medium`).

    Raises
    ------
    InputError
        No grid beside the file, or anything wrong in the files (one line).

    Examples
    --------
    A one-cell case written formatted, its report steps in non-unified files, opened from one
    of them:

    >>> import numpy as np, os, tempfile, resfo
    >>> d, F = tempfile.mkdtemp(), resfo.Format.FORMATTED
    >>> gh = np.zeros(100, np.int32); gh[:4] = 1
    >>> coord = np.array([0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1],
    ...                  np.float32)
    >>> resfo.write(os.path.join(d, "C.FEGRID"), [("GRIDHEAD", gh), ("COORD   ", coord),
    ...     ("ZCORN   ", np.repeat(np.float32([0, 1]), 4)), ("ENDGRID ", np.zeros(0, np.int32))], F)
    >>> head = np.zeros(411, np.int32); head[8:12] = 1
    >>> resfo.write(os.path.join(d, "C.FINIT"), [("INTEHEAD", head),
    ...                                          ("PORO    ", np.float32([0.25]))], F)
    >>> for k in (1, 2):
    ...     head[64:67] = (1, k, 2001)
    ...     resfo.write(os.path.join(d, f"C.F{k:04d}"),
    ...                 [("INTEHEAD", head), ("SWAT    ", np.float32([k / 4]))], F)
    >>> case = load_case(os.path.join(d, "C.F0002"))
    >>> case.step_dates, case.meta["unrst_seqnum"], case.meta["restart"]["kind"]
    (['2001-01-01', '2001-02-01'], [1, 2], 'non-unified')
    >>> float(case.properties["PORO"][0, 0, 0]), float(case.steps[1]["SWAT"][0, 0, 0])
    (0.25, 0.5)
    """
    files = case_files(path)
    old_grid = files.grid.suffix.upper() in GRID_FILE_SUFFIXES
    grid = read_ecl_grid(files.grid) if old_grid else read_egrid(files.grid)
    notes = grid.meta.setdefault("notes", [])
    if files.init is None:
        stem = files.grid.name[: -len(files.grid.suffix)]
        init = f"{stem}.FINIT" if _formatted_name(files.grid) else f"{stem}.INIT"
        if files.restart is None:
            unrst = f"{stem}.{'F' if _formatted_name(files.grid) else ''}UNRST"
            notes.append(f"grid file alone: geometry only ({init} would add its properties, "
                         f"{unrst} its report steps)")
            grid.meta["grid_alone"] = True
        else:
            notes.append(f"no INIT beside the grid: {init} would add its properties")
    else:
        grid.properties = read_init(files.init, grid)
        grid.meta["init"] = str(files.init)
    if not notes:
        del grid.meta["notes"]
    if files.restart is not None:
        _attach_steps(grid, files, keywords, eager_bytes, progress, Path(path))
        if grid.dual_media or grid.refinements:
            grid.check_steps()
    return grid


def _attach_steps(grid: CornerPointGrid, files: CaseFiles, keywords, eager_bytes: int,
                  progress: Progress | None, given: Path) -> None:
    """The report steps of ``files.restart`` in ``grid`` (and in its media and LGRs); a
    non-unified file opened itself is the step shown by default (``meta["default_step"]``)."""
    index = UnrstIndex(files.restart, grid, keywords)
    first = index.view(medium=grid.medium) if grid.dual_media else index
    grid.meta.update(unrst=first, unrst_path=str(index.path),
                     step_keywords=list(first.keywords), unrst_seqnum=list(index.seqnum),
                     restart=files.restart_meta())
    grid.step_dates = list(index.dates)
    eager = restart_bytes(first) * max(1, len(grid.media)) <= eager_bytes
    for name, medium in grid.dual_media.items():
        view = index.view(medium=name)
        medium.meta = {"unrst": view, "step_keywords": list(view.keywords)}
        medium.steps = read_steps(view, progress) if eager else list(lazy_steps(view))
    if grid.dual_media:
        grid.steps = grid.dual_media[grid.medium].steps
    elif eager:
        grid.steps = read_steps(index, progress)
        grid.check_steps()
    else:
        grid.steps = list(lazy_steps(index))
    refinement_steps(grid, index, eager_bytes)
    names = [f.name for f in index.files]
    if RESTART_SUFFIX.fullmatch(given.suffix) and given.name in names:
        report = report_number(given)
        k = names.index(given.name)
        grid.meta["default_step"] = k
        grid.meta.setdefault("notes", []).append(
            f"opened {given.name}: report {report} (step {k}) is shown unless a step is given")


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
