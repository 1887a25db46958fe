"""ECLIPSE/OPM summary files: SMSPEC + UNSMRY (or non-unified ``.S0001`` ...), binary or
formatted (``.FSMSPEC`` + ``.FUNSMRY`` / ``.A0001`` ...), into a
:class:`~geoshade.models.summary_vectors.SummaryTable`.

The SMSPEC says what each value of a ``PARAMS`` record is (``KEYWORDS``, ``WGNAMES`` or
``NAMES``, ``NUMS``, ``UNITS``; ``DIMENS`` gives the grid size that turns a block's number into
``i,j,k``; ``STARTDAT`` the start); the UNSMRY holds, for every ministep, a ``MINISTEP`` and a
``PARAMS`` record, report steps starting at each ``SEQHDR``. Every record header is checked
before its array is read (:func:`geoshade.io.grids.ecl_records.scan`: a damaged or truncated
file is one line naming the record, never a silent short table), values are kept as the file
stores them (float32), and the tests compare them with resfo's reading.

Any file of a case leads to its summary (``CASE.DATA``, ``CASE.EGRID``, ``CASE.UNRST``,
``CASE.X0012``, ``CASE.UNSMRY`` ... find ``CASE.SMSPEC`` beside them): :func:`summary_files`.

>>> import numpy as np, os, tempfile
>>> d = tempfile.mkdtemp()
>>> write_summary(os.path.join(d, "C.SMSPEC"), [("TIME", "", 0, "DAYS"),
...               ("FOPR", "", 0, "SM3/DAY"), ("WBHP", "P1", 0, "BARSA")],
...               np.array([[1, 100, 250], [31, 90, 240]], np.float32), dims=(2, 2, 1))
>>> t = read_summary(os.path.join(d, "C.SMSPEC"))
>>> t.keys, t["WBHP:P1"].tolist(), t.iso_dates()
(('TIME', 'FOPR', 'WBHP:P1'), [250.0, 240.0], ['2000-01-02T00:00:00', '2000-02-01T00:00:00'])
"""

from __future__ import annotations

import csv
import datetime
import io
import mmap
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import resfo

from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import RecordError, scan
from geoshade.io.paths import check_file
from geoshade.models.summary_vectors import (
    UNIT_SYSTEMS,
    SummaryTable,
    SummaryVector,
    match_vectors,
)

#: the name ECLIPSE writes for "no well/group" in WGNAMES
NO_NAME = ":+:+:+:+"
#: keywords of the "misc" kind whatever their first letter (resdata's special variables)
MISC = frozenset({"NEWTON", "NAIMFRAC", "NLINEARS", "NLINSMIN", "NLINSMAX", "ELAPSED", "MAXDPR",
                  "MAXDSO", "MAXDSG", "MAXDSW", "STEPTYPE", "WNEWTON"})
#: flow between two regions (NUMS = r1 + 32768 * (r2 + 10))
_REGION_FLOW = re.compile(r"R[OGW]F[RT][-+LG]?")
_KIND_OF_LETTER = {"A": "aquifer", "B": "block", "C": "connection", "F": "field", "G": "group",
                   "N": "network", "R": "region", "S": "segment", "W": "well"}
_LOCAL = {"B": "local-block", "C": "local-connection", "W": "local-well"}
#: summary data files: unified, then non-unified (``S``/``A`` + report number)
_NON_UNIFIED = {"": "S", "F": "A"}


@dataclass
class SummaryFiles:
    """The summary files of one case.

    spec:      Path          the SMSPEC or FSMSPEC
    data:      list of Path  the UNSMRY (or FUNSMRY), or the non-unified files in report order
    formatted: bool          whether the spec's name says formatted
    """

    spec: Path
    data: list[Path] = field(default_factory=list)
    formatted: bool = False

    def describe(self) -> str:
        """``CASE.SMSPEC + CASE.UNSMRY`` (non-unified: the first and last file and their count)."""
        if len(self.data) == 1:
            return f"{self.spec.name} + {self.data[0].name}"
        return (f"{self.spec.name} + {self.data[0].name} … {self.data[-1].name} "
                f"({len(self.data)} files)")


@dataclass
class SummarySpec:
    """What an SMSPEC says: every valid vector (with its position in PARAMS), the start, the
    unit system, the grid size; ``skipped``: entries that name no vector (ECLIPSE's fill)."""

    path: Path
    vectors: tuple[SummaryVector, ...]
    start: datetime.datetime
    unit_system: str
    dims: tuple[int, int, int]
    nlist: int
    skipped: int = 0
    restart_of: str = ""

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(v.key for v in self.vectors)

    def match(self, patterns: Iterable[str]) -> list[SummaryVector]:
        """The vectors ``patterns`` name (exact names or wildcards such as ``WOPR:*``); an
        unknown one is one line naming it and the nearest names."""
        by_key = {v.key: v for v in self.vectors}
        return [by_key[k] for k in match_vectors(self.keys, patterns, str(self.path))]


# --- the files of a case -----------------------------------------------------------------------
def _stem(p: Path) -> str:
    return p.name[: -len(p.suffix)] if p.suffix else p.name


def _formatted_name(p: Path) -> bool:
    s = p.suffix.upper()
    return s in (".FSMSPEC", ".FUNSMRY", ".FEGRID", ".FINIT", ".FUNRST", ".FGRID") or bool(
        re.fullmatch(r"\.[FA]\d{4}", s))


def _beside(folder: Path, stem: str, suffix: str) -> Path | None:
    for s in (suffix, suffix.lower()):
        c = folder / (stem + s)
        if c.exists():
            return check_file(c, f"an ECLIPSE {suffix.lstrip('.')} file")
    return None


def _non_unified(folder: Path, stem: str, letter: str) -> list[Path]:
    pattern = re.compile(re.escape(stem) + rf"\.[{letter}{letter.lower()}](\d{{4}})")
    found: dict[int, Path] = {}
    try:
        names = sorted(e.name for e in os.scandir(folder))
    except OSError:
        return []
    for name in names:
        m = pattern.fullmatch(name)
        if m:
            found.setdefault(int(m[1]), folder / name)
    return [found[n] for n in sorted(found)]


def summary_files(path) -> SummaryFiles:
    """The summary files of the case ``path`` belongs to: any of its files (``CASE.SMSPEC``,
    ``CASE.DATA``, ``CASE.EGRID``, ``CASE.UNRST``, ``CASE.X0012``, ``CASE.S0003``, formatted
    forms ...); the SMSPEC and its data are looked for beside it under the case's name, those
    of the given file's format first.

    Raises
    ------
    InputError
        No such file, or no SMSPEC or no summary data beside it (one line saying what was looked
        for where).

    Examples
    --------
    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> for n in ("C.DATA", "C.SMSPEC", "C.S0001", "C.S0002"):
    ...     open(os.path.join(d, n), "wb").close()
    >>> summary_files(os.path.join(d, "C.DATA")).describe()
    'C.SMSPEC + C.S0001 … C.S0002 (2 files)'
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "a file of an ECLIPSE/OPM case")
    folder, stem = p.parent, _stem(p)
    formatted = _formatted_name(p)
    prefs = ("F", "") if formatted else ("", "F")
    if p.suffix.upper() in (".SMSPEC", ".FSMSPEC"):
        spec = p
    else:
        spec = next((s for s in (_beside(folder, stem, f".{f}SMSPEC") for f in prefs) if s),
                    None)
    if spec is None:
        raise InputError(f"{path}: no summary of case {stem} beside it (looked for "
                         f"{stem}.SMSPEC and {stem}.FSMSPEC in {folder}); the run wrote no "
                         "summary, or under another name")
    f_spec = "F" if _formatted_name(spec) else ""
    order = (f_spec, "F" if not f_spec else "")
    data: list[Path] = []
    if p.suffix.upper() in (".UNSMRY", ".FUNSMRY"):
        data = [p]
    for f in order:
        if data:
            break
        u = _beside(folder, stem, f".{f}UNSMRY")
        data = [u] if u else _non_unified(folder, stem, _NON_UNIFIED[f])
    if not data:
        raise InputError(f"{spec}: no summary data beside it (looked for {stem}.UNSMRY, "
                         f"{stem}.FUNSMRY and {stem}.S0001 ... in {folder})")
    for d in data:
        check_file(d, "an ECLIPSE summary data file")
    return SummaryFiles(spec, data, bool(f_spec))


def summary_alone(path) -> bool:
    """Whether ``path`` (a summary file) has no grid of its case beside it (no EGRID, FEGRID,
    GRID or FGRID): :func:`geoshade.load` then reads it as a summary, else as the case's grid
    (the format table's test).

    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> open(os.path.join(d, "C.SMSPEC"), "wb").close()
    >>> summary_alone(os.path.join(d, "C.SMSPEC"))
    True
    >>> open(os.path.join(d, "C.EGRID"), "wb").close()
    >>> summary_alone(os.path.join(d, "C.SMSPEC"))
    False
    """
    p = Path(path)
    stem = _stem(p)
    return not any((p.parent / (stem + s)).exists() or (p.parent / (stem + s.lower())).exists()
                   for s in (".EGRID", ".FEGRID", ".GRID", ".FGRID"))


# --- SMSPEC ------------------------------------------------------------------------------------
def _text(a) -> list[str]:
    return [(x.decode("latin-1") if isinstance(x, bytes) else str(x)).strip() for x in a]


def vector_of(keyword: str, wgname: str, num: int, dims: tuple[int, int, int],
              lgr: str = "", numl: tuple[int, int, int] | None = None
              ) -> tuple[str, str, str, tuple[int, int, int] | None] | None:
    """``(key, kind, name, ijk)`` of one SMSPEC entry, named as ECLIPSE names it, or None
    where the entry names no vector (a well vector for ``:+:+:+:+``, a block 0).

    >>> vector_of("BPR", NO_NAME, 1095, (40, 64, 14))
    ('BPR:15,28,1', 'block', '', (15, 28, 1))
    >>> vector_of("WOPR", "OP_1", 0, (1, 1, 1))[:2], vector_of("WOPR", NO_NAME, 0, (1, 1, 1))
    (('WOPR:OP_1', 'well'), None)
    >>> vector_of("ROFT", "", 1 + 32768 * 12, (1, 1, 1))[0]
    'ROFT:1-2'
    """
    kw = keyword
    name = "" if wgname in ("", NO_NAME) else wgname
    letter = kw[:1]
    if kw in MISC or (letter not in _KIND_OF_LETTER and letter != "L"):
        return kw, "misc", "", None

    def ijk(n: int, d: tuple[int, int, int]) -> tuple[int, int, int] | None:
        if n < 1 or n > d[0] * d[1] * d[2]:
            return None
        n -= 1
        return n % d[0] + 1, n // d[0] % d[1] + 1, n // (d[0] * d[1]) + 1

    if letter == "L" and kw[1:2] in _LOCAL:
        kind = _LOCAL[kw[1:2]]
        if not lgr or numl is None:
            return None
        loc = ",".join(str(v) for v in numl)
        if kind == "local-well":
            return (f"{kw}:{lgr}:{name}", kind, name, None) if name else None
        if kind == "local-connection":
            return (f"{kw}:{lgr}:{name}:{loc}", kind, name, numl) if name else None
        return f"{kw}:{lgr}:{loc}", kind, "", numl
    if letter == "L":
        return kw, "misc", "", None
    kind = _KIND_OF_LETTER[letter]
    if kind == "field":
        return kw, kind, "", None
    if kind in ("well", "group", "network"):
        return (f"{kw}:{name}", kind, name, None) if name else None
    if kind == "block":
        at = ijk(num, dims)
        return (f"{kw}:{at[0]},{at[1]},{at[2]}", kind, "", at) if at else None
    if kind == "connection":
        at = ijk(num, dims)
        return (f"{kw}:{name}:{at[0]},{at[1]},{at[2]}", kind, name, at) if at and name else None
    if kind == "segment":
        return (f"{kw}:{name}:{num}", kind, name, None) if name and num > 0 else None
    if kind == "region" and _REGION_FLOW.fullmatch(kw):
        r1, r2 = num % 32768, num // 32768 - 10
        return (f"{kw}:{r1}-{r2}", "region-flow", "", None) if r1 > 0 and r2 > 0 else None
    return (f"{kw}:{num}", kind, "", None) if num > 0 else None  # region, aquifer


def read_spec(path) -> SummarySpec:
    """What the SMSPEC (or FSMSPEC) ``path`` says; one line for a damaged or incomplete one.

    >>> import numpy as np, os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "C.SMSPEC")
    >>> write_summary(f, [("TIME", "", 0, "DAYS"), ("BPR", "", 5, "BARSA")],
    ...               np.zeros((1, 2), np.float32), dims=(2, 2, 2))
    >>> [(v.key, v.kind, v.unit) for v in read_spec(f).vectors]
    [('TIME', 'misc', 'DAYS'), ('BPR:1,1,2', 'block', 'BARSA')]
    """
    p = check_file(path, "an ECLIPSE SMSPEC file")
    recs: dict = {}
    for rec in scan(p):
        recs.setdefault(rec.keyword, rec)
    names = "WGNAMES" if "WGNAMES" in recs else "NAMES"
    for kw in ("DIMENS", "KEYWORDS", names, "NUMS", "UNITS", "STARTDAT"):
        if kw not in recs:
            raise InputError(f"{p}: {kw if kw != 'NAMES' else 'WGNAMES or NAMES'}: not found; "
                             "expected an SMSPEC file (DIMENS, KEYWORDS, WGNAMES, NUMS, UNITS, "
                             "STARTDAT)")
    dimens = recs["DIMENS"].read("i")
    if dimens.size < 4:
        raise InputError(f"{p}: DIMENS: expected at least 4 values (count, nx, ny, nz), got "
                         f"{dimens.size}")
    nlist, dims = int(dimens[0]), (int(dimens[1]), int(dimens[2]), int(dimens[3]))
    keywords = _text(recs["KEYWORDS"].read("S"))
    wgnames = _text(recs[names].read("S"))
    nums = recs["NUMS"].read("i").astype(np.int64)
    units = _text(recs["UNITS"].read("S"))
    for kw, arr in (("KEYWORDS", keywords), (names, wgnames), ("NUMS", nums), ("UNITS", units)):
        if len(arr) != nlist:
            raise InputError(f"{p}: {kw}: {len(arr)} entries; expected {nlist} (DIMENS item 1)")
    lgrs = _text(recs["LGRS"].read("S")) if "LGRS" in recs else [""] * nlist
    numl = [recs[k].read("i") if k in recs else np.zeros(nlist, np.int32)
            for k in ("NUMLX", "NUMLY", "NUMLZ")]
    start = _start(p, recs["STARTDAT"].read("i"))
    head = recs["INTEHEAD"].read("i") if "INTEHEAD" in recs else np.zeros(0, np.int32)
    unit_system = UNIT_SYSTEMS.get(int(head[0]), "") if head.size else ""
    restart = "".join(_text(recs["RESTART"].read("S"))) if "RESTART" in recs else ""
    vectors: list[SummaryVector] = []
    seen: set[str] = set()
    skipped = 0
    for i in range(nlist):
        loc = (int(numl[0][i]), int(numl[1][i]), int(numl[2][i])) if len(lgrs) == nlist and \
            lgrs[i] else None
        got = vector_of(keywords[i], wgnames[i], int(nums[i]), dims,
                        lgrs[i] if len(lgrs) == nlist else "", loc)
        if got is None or got[0] in seen or not keywords[i]:
            skipped += 1
            continue
        key, kind, name, ijk = got
        seen.add(key)
        vectors.append(SummaryVector(key, keywords[i], kind, units[i], name, int(nums[i]), ijk,
                                     i))
    return SummarySpec(p, tuple(vectors), start, unit_system, dims, nlist, skipped, restart)


def _start(p: Path, s: np.ndarray) -> datetime.datetime:
    """STARTDAT: day, month, year (hour, minute, microseconds)."""
    if s.size < 3:
        raise InputError(f"{p}: STARTDAT: expected day, month, year, got {s.tolist()}")
    day, month, year = (int(v) for v in s[:3])
    hour, minute, micro = (int(s[k]) if s.size > k else 0 for k in (3, 4, 5))
    try:
        return datetime.datetime(year, month, day) + datetime.timedelta(
            hours=hour, minutes=minute, microseconds=micro)
    except (ValueError, OverflowError):
        raise InputError(f"{p}: STARTDAT: {s.tolist()} is not a date (expected day, month, "
                         "year)") from None


# --- UNSMRY ------------------------------------------------------------------------------------
def case_spec(model) -> SummarySpec:
    """The SMSPEC of the case a grid or field was read from (its ``meta["source"]``, else its
    name); one line when the case has no summary files.

    >>> import numpy as np, os, tempfile
    >>> from types import SimpleNamespace
    >>> d = tempfile.mkdtemp()
    >>> write_summary(os.path.join(d, "C.SMSPEC"), [("TIME", "", 0, "DAYS"),
    ...               ("FOPR", "", 0, "SM3/DAY")], np.zeros((1, 2), np.float32))
    >>> case_spec(SimpleNamespace(meta={"source": os.path.join(d, "C.SMSPEC")}, name="C")).keys
    ('TIME', 'FOPR')
    >>> case_spec(SimpleNamespace(meta={}, name="synthetic 4x3x2"))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: summary: synthetic 4x3x2 was not read from a case's files; it \
has no summary
    """
    meta = getattr(model, "meta", None) or {}
    source = meta.get("source") or getattr(model, "source", None)
    if not source:
        raise InputError(f"summary: {getattr(model, 'name', None) or 'the model'} was not read "
                         "from a case's files; it has no summary")
    return read_spec(summary_files(source).spec)


def read_summary(path, vectors: Iterable[str] | None = None) -> SummaryTable:
    """The summary of the case ``path`` belongs to (any of its files, see
    :func:`summary_files`), every ministep.

    Parameters
    ----------
    path : str or Path
        ``CASE.SMSPEC``, ``CASE.FSMSPEC``, ``CASE.UNSMRY``, ``CASE.DATA``, ``CASE.EGRID`` ...
    vectors : list of str, optional
        The vectors to keep: names (``WBHP:PROD``) or wildcards (``WOPR:*``); default all. An
        unknown name is one line naming it and the nearest names, before the data is read.

    Returns
    -------
    SummaryTable
        Values as the file stores them (float32), times from TIME (days; hours in LAB units
        are converted) or, without TIME, from DAY/MONTH/YEAR.

    Examples
    --------
    >>> import numpy as np, os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "C.FSMSPEC")
    >>> write_summary(f, [("TIME", "", 0, "DAYS"), ("WOPR", "A", 0, "SM3/DAY"),
    ...               ("WOPR", "B", 0, "SM3/DAY")], np.ones((3, 3), np.float32), formatted=True)
    >>> read_summary(f, ["WOPR:*"]).keys
    ('WOPR:A', 'WOPR:B')
    """
    files = summary_files(path)
    spec = read_spec(files.spec)
    chosen = list(spec.vectors) if vectors is None else spec.match(vectors)
    by_kw = {v.key: v for v in spec.vectors}
    time = by_kw.get("TIME")
    clock = [by_kw[k] for k in ("DAY", "MONTH", "YEAR") if k in by_kw]
    if time is None and len(clock) < 3:
        raise InputError(f"{files.spec}: TIME: not among the vectors (nor DAY, MONTH, YEAR); "
                         "expected the simulated time of each ministep")
    need = [time] if time is not None else clock
    cols = np.array([v.index for v in [*need, *chosen]], np.int64)
    rows, reports, ministeps = _read_params(files.data, spec.nlist, cols)
    tcols = rows[:, : len(need)].astype(np.float64)
    values = rows[:, len(need):]
    if time is not None:
        days = tcols[:, 0] / (24.0 if time.unit.upper() in ("HOURS", "HOUR", "HR") else 1.0)
    else:
        days = _days_from_clock(files.spec, spec.start, tcols)
    bad = np.flatnonzero(np.diff(days) < 0)
    if bad.size or not np.all(np.isfinite(days)):
        at = int(bad[0]) + 1 if bad.size else int(np.flatnonzero(~np.isfinite(days))[0])
        raise InputError(f"{files.data[0]}: ministep {at}: the time goes backwards or is not a "
                         f"number ({days[at]} days); a damaged file")
    meta = {"format": "formatted" if files.formatted else "unformatted",
            "files": [str(files.spec), *(str(d) for d in files.data)],
            "summary": files.describe(), "skipped": spec.skipped, "dims": spec.dims}
    if spec.restart_of:
        meta["restart_of"] = spec.restart_of
    if not reports.any():  # no SEQHDR: each ministep its own report step
        reports = np.arange(1, len(days) + 1)
    return SummaryTable(days, values, chosen, spec.start, reports, ministeps, spec.unit_system,
                        str(files.spec), meta)


def _days_from_clock(p: Path, start: datetime.datetime, clock: np.ndarray) -> np.ndarray:
    try:
        dates = [datetime.datetime(int(y), int(m), int(d)) for d, m, y in clock]
    except (ValueError, OverflowError):
        raise InputError(f"{p}: DAY/MONTH/YEAR: not dates; expected the date of each "
                         "ministep") from None
    return np.array([(d - start).total_seconds() / 86400.0 for d in dates], np.float64)


def _read_params(data: Sequence[Path], nlist: int, cols: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Columns ``cols`` of every PARAMS record of ``data`` (in order), the report step (SEQHDR
    count) and ministep number of each."""
    rows: list[np.ndarray] = []
    reports: list[int] = []
    ministeps: list[int] = []
    seq, mini = 0, 0
    for f in data:
        try:
            recs = list(scan(f))  # every header checked before any value is read
            fast = _binary_params(f, recs, nlist, cols)
            if fast is not None:  # one mapping of the file, no reader per record
                vals, kinds, minis = fast
                seqs = seq + np.cumsum(kinds == 1)
                at = kinds == 2
                rows.append(vals)
                reports += seqs[at].tolist()
                ministeps += minis.tolist()
                seq = int(seqs[-1]) if seqs.size else seq
                mini = int(minis[-1]) if minis.size else mini
                continue
            for rec in recs:
                if rec.keyword == "SEQHDR":
                    seq += 1
                elif rec.keyword == "MINISTEP":
                    m = rec.read("i")
                    mini = int(m[0]) if m.size else mini + 1
                elif rec.keyword == "PARAMS":
                    _check_length(f, rec.length, nlist, mini)
                    rows.append(rec.read("f")[cols][None, :])
                    reports.append(seq)
                    ministeps.append(mini)
        except RecordError as err:
            raise InputError(str(err)) from None
    if not reports:
        raise InputError(f"{data[0]}: no PARAMS record; expected the values of at least one "
                         "ministep")
    dtype = rows[0].dtype
    return (np.concatenate(rows).astype(dtype, copy=False), np.asarray(reports, np.int64),
            np.asarray(ministeps, np.int64))


def _check_length(f: Path, length: int, nlist: int, mini: int) -> None:
    if length < nlist:
        raise InputError(f"{f}: PARAMS of ministep {mini}: {length} values; expected {nlist} "
                         "(the SMSPEC's DIMENS)")


#: values per block of a binary record, and the bytes of a block's two markers
_BLOCK, _MARKS = 1000, 8


def _binary_params(f: Path, recs: list, nlist: int, cols: np.ndarray):
    """``(values (n, len(cols)) float32, kinds, ministeps)`` of a binary UNSMRY read through
    one memory map (``kinds``: 1 SEQHDR, 2 PARAMS, 0 other, per record), the block markers
    around each value read checked; None where the file is formatted or its PARAMS are not
    all REAL records of one length (then each record is read by itself)."""
    params = [r for r in recs if r.keyword == "PARAMS"]
    if not params or recs[0].formatted or any(
            r.type != "REAL" or r.length != params[0].length for r in params) or any(
            r.keyword == "MINISTEP" and (r.type != "INTE" or r.length != 1) for r in recs):
        return None
    length = params[0].length
    kinds = np.array([1 if r.keyword == "SEQHDR" else 2 if r.keyword == "PARAMS" else 0
                      for r in recs], np.int8)
    plan = []  # per block read: (block, its values, where they go, which of them)
    for blk in np.unique(cols // _BLOCK):
        where = np.flatnonzero(cols // _BLOCK == blk)
        count = min(_BLOCK, length - int(blk) * _BLOCK)
        plan.append((int(blk) * (_BLOCK * 4 + _MARKS), count, where,
                     cols[where] - int(blk) * _BLOCK))
    out = np.empty((len(params), cols.size), np.float32)
    minis: list[int] = []
    mini = 0
    with open(f, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as buf:
        def marker(at: int) -> int:
            return int.from_bytes(buf[at:at + 4], "big", signed=True)

        def bad(rec, at: int, want: int) -> RecordError:
            return RecordError(f"{f}: {rec.keyword}: damaged record at byte {rec.start} (a "
                               f"block marker at byte {at} reads {marker(at)}, not its block's "
                               f"size {want})", rec.start, rec.keyword)

        k = 0
        for rec in recs:
            if rec.keyword == "MINISTEP":
                at = rec.start + 24
                if marker(at) != 4 or marker(at + 8) != 4:
                    raise bad(rec, at if marker(at) != 4 else at + 8, 4)
                mini = marker(at + 4)
            elif rec.keyword == "PARAMS":
                _check_length(f, length, nlist, mini)
                base = rec.start + 24
                for offset, count, where, local in plan:
                    at = base + offset
                    if marker(at) != 4 * count or marker(at + 4 + 4 * count) != 4 * count:
                        raise bad(rec, at if marker(at) != 4 * count else at + 4 + 4 * count,
                                  4 * count)
                    vals = np.frombuffer(buf, ">f4", count, at + 4)
                    out[k, where] = vals[local]
                    del vals
                minis.append(mini)
                k += 1
    return out, kinds, np.asarray(minis, np.int64)


def describe_summary(table: SummaryTable, stats: bool = True) -> dict:
    """``geoshade info`` of a summary: its vectors by kind, ministeps, report steps, time span.

    >>> import numpy as np, datetime
    >>> t = SummaryTable([1.0], np.zeros((1, 2), np.float32),
    ...                  [SummaryVector("FPR", "FPR", "field"),
    ...                   SummaryVector("WBHP:P", "WBHP", "well", name="P")],
    ...                  datetime.datetime(2000, 1, 1))
    >>> describe_summary(t)["vectors"]
    '2 (field 1, well 1)'
    """
    kinds: dict[str, int] = {}
    for v in table.vectors:
        kinds[v.kind] = kinds.get(v.kind, 0) + 1
    dates = table.iso_dates()
    return {"kind": "summary", "name": Path(str(table.name)).name, "source": str(table.name),
            "format": "ECLIPSE/OPM summary, " + table.meta.get("format", "unformatted"),
            "files": table.meta.get("summary", ""), "units": table.unit_system,
            "vectors": f"{len(table.vectors)} ("
                       + ", ".join(f"{k} {n}" for k, n in kinds.items()) + ")",
            "ministeps": table.nsteps, "reports": len(table.report_index()),
            "time": f"{dates[0]} – {dates[-1]}" if dates else "",
            "see": f"geoshade summary {Path(str(table.name)).name} --list"}


# --- output ------------------------------------------------------------------------------------
def csv_text(table: SummaryTable) -> str:
    """The table as CSV: ``date`` (ISO, to the second), ``days``, then one column per vector
    named as ECLIPSE names it (``"BPR:1,2,3"`` quoted); values as the file stores them,
    written so that they read back exactly (float32's shortest text).

    >>> import numpy as np, datetime
    >>> from geoshade.models.summary_vectors import SummaryTable, SummaryVector
    >>> t = SummaryTable([0.25], np.array([[0.1]], np.float32),
    ...                  [SummaryVector("BPR:1,2,3", "BPR", "block")],
    ...                  datetime.datetime(2000, 1, 1))
    >>> print(csv_text(t), end="")
    date,days,"BPR:1,2,3"
    2000-01-01T06:00:00,0.25,0.1
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["date", "days", *table.keys])
    cols = [table.iso_dates(), [str(x) for x in table.days.tolist()]]
    cols += [[str(x) for x in table.values[:, i]] for i in range(len(table.vectors))]
    w.writerows(zip(*cols, strict=True))
    return buf.getvalue()


def listing(spec: SummarySpec, patterns: Iterable[str] | None = None) -> list[str]:
    """One line per vector (name, unit, kind, and the well/group it belongs to), those
    ``patterns`` name or all."""
    vectors = list(spec.vectors) if patterns is None else spec.match(patterns)
    wk = max((len(v.key) for v in vectors), default=4)
    wu = max((len(v.unit) for v in vectors), default=4)
    return [f"{v.key:<{wk}}  {v.unit or '-':<{wu}}  {v.kind}" for v in vectors]


def write_summary(path, entries: Sequence[tuple[str, str, int, str]], params: np.ndarray,
                  start: tuple[int, int, int] = (1, 1, 2000),
                  dims: tuple[int, int, int] = (1, 1, 1),
                  reports: Sequence[int] | None = None, formatted: bool = False,
                  unit_system: int = 1) -> None:
    """Write an SMSPEC and its UNSMRY (``formatted``: FSMSPEC + FUNSMRY) through resfo: small
    cases for tests and examples.

    ``entries``: (keyword, well or group name, NUMS, unit) per vector; ``params``: (n, m)
    values per ministep; ``reports``: the report step of each ministep (default one each).
    The UNSMRY is written beside ``path`` with the same name.
    """
    p = Path(path)
    fmt = resfo.Format.FORMATTED if formatted else resfo.Format.UNFORMATTED
    params = np.asarray(params, np.float32)
    n = len(entries)
    spec = [("INTEHEAD", np.array([unit_system, 100], np.int32)),
            ("RESTART ", np.array([b" " * 8] * 9, dtype="|S8")),
            ("DIMENS  ", np.array([n, *dims, 0, 0], np.int32)),
            ("KEYWORDS", np.array([e[0].ljust(8).encode() for e in entries], dtype="|S8")),
            ("WGNAMES ", np.array([(e[1] or NO_NAME).ljust(8).encode() for e in entries],
                                  dtype="|S8")),
            ("NUMS    ", np.array([e[2] for e in entries], np.int32)),
            ("UNITS   ", np.array([e[3].ljust(8).encode() for e in entries], dtype="|S8")),
            ("STARTDAT", np.array([*start, 0, 0, 0], np.int32))]
    resfo.write(p, spec, fileformat=fmt)
    reports = list(range(1, len(params) + 1)) if reports is None else list(reports)
    data: list = []
    last = None
    for k, row in enumerate(params):
        if reports[k] != last:
            data.append(("SEQHDR  ", np.array([reports[k]], np.int32)))
            last = reports[k]
        data += [("MINISTEP", np.array([k + 1], np.int32)), ("PARAMS  ", row)]
    resfo.write(p.with_name(_stem(p) + (".FUNSMRY" if formatted else ".UNSMRY")), data,
                fileformat=fmt)


__all__ = ["NO_NAME", "SummaryFiles", "SummarySpec", "case_spec", "csv_text", "describe_summary",
           "listing", "read_spec", "read_summary", "summary_alone", "summary_files", "vector_of",
           "write_summary"]
