"""Simulation wells of ECLIPSE/OPM restart files (UNRST, or the non-unified ``.X0001`` …):
IWEL, ICON, ZWEL.

Every report step of a restart file that has wells carries, after its ``INTEHEAD``:

- ``IWEL``: ``NIWELZ`` integers per well (INTEHEAD item 25; 0-based index 24); item 0, 1: the
  well head's I, J (1-based); 4: the number of connections; 6: the type (1 producer, 2 oil,
  3 water, 4 gas injector); 10: the status (> 0 open, else shut: OPM writes -1000);
- ``ZWEL``: ``NZWELZ`` 8-character words per well (index 27), the first is the well's name;
- ``ICON``: ``NICONZ`` integers (index 32) per connection, ``NCWMAX`` connection slots per
  well (index 17): item 0 the connection's sequence number (0: an empty slot), 1–3 its cell
  I, J, K (1-based), 5 its status (> 0 open, else shut).

``NWELLS`` is INTEHEAD index 16. These are the indices of ``resdata`` (``well_const.h``) and of
OPM's ``VectorItems`` (``intehead.hpp``, ``well.hpp``, ``connection.hpp``); a connection is read
as ``resdata`` reads it (slots below IWEL's count with a positive sequence number).  A K beyond
NZ in a dual-porosity run (NZ..2NZ: the fracture cells) is read as the matrix cell above it.
Records inside an ``LGR`` … ``ENDLGR`` section belong to a local grid and are skipped.

The file's record headers are walked once (:func:`geoshade.io.grids.ecl_records.scan`, every header
checked) to find the four records of each report step; a step's wells are read only when
asked for (``index[k]``, a few hundred bytes per well), so the file is never read whole.  Every
damaged or inconsistent record is one line naming the file, the keyword and the step.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import Record, RecordError, scan
from geoshade.io.grids.ecl_restart import step_time
from geoshade.models.wells import UNKNOWN_TYPE, WELL_TYPES, SimWell, SimWells

#: INTEHEAD indices (0-based)
NWELLS, NCWMAX, NIWELZ, NZWELZ, NICONZ = 16, 17, 24, 27, 32
#: IWEL items (0-based)
IWEL_HEAD_I, IWEL_HEAD_J, IWEL_NCONN, IWEL_TYPE, IWEL_STATUS = 0, 1, 4, 6, 10
#: ICON items (0-based)
ICON_SEQ, ICON_I, ICON_J, ICON_K, ICON_STATUS = 0, 1, 2, 3, 5
_WELL_KEYWORDS = ("INTEHEAD", "IWEL", "ICON", "ZWEL")
#: key of the index in ``grid.meta``
META_KEY = "restart_wells"
#: a non-unified restart file's suffix: its report number
_REPORT = re.compile(r"\.[XxFf](\d{4})$")


@dataclass
class _Step:
    seqnum: int
    path: Path
    records: dict[str, Record] = field(default_factory=dict)
    complete: bool = False


class RestartWellIndex:
    """Where the well records of each report step of a UNRST lie; ``index[k]`` reads step
    ``k``'s wells as :class:`~geoshade.models.wells.SimWells` (the last few are cached).

    Parameters
    ----------
    path : str, Path or list of them
        The unified restart file (``.UNRST``, or a formatted ``.FUNRST``), or the non-unified
        files in report order (``.X0001`` …; a file without SEQNUM is one step, its report
        number from the suffix).
    dims : (nx, ny, nz), optional
        The grid's size: completion cells are checked against it.
    nsteps : int, optional
        Keep only the first ``nsteps`` report steps (those of the grid's ``steps``).

    Examples
    --------
    >>> import os, tempfile, numpy as np, resfo
    >>> f = os.path.join(tempfile.mkdtemp(), "W.UNRST")
    >>> head = np.zeros(411, np.int32); head[[16, 17, 24, 27, 32]] = (1, 2, 155, 3, 26)
    >>> iwel = np.zeros(155, np.int32); iwel[[0, 1, 4, 6, 10]] = (2, 3, 1, 3, 1)
    >>> icon = np.zeros(52, np.int32); icon[[0, 1, 2, 3, 5]] = (1, 2, 3, 4, 1)
    >>> zwel = np.array([b"WI_1    ", b"        ", b"        "])
    >>> resfo.write(f, [("SEQNUM  ", np.array([1], np.int32)), ("INTEHEAD", head),
    ...                 ("IWEL    ", iwel), ("ZWEL    ", zwel), ("ICON    ", icon)])
    >>> w = RestartWellIndex(f, dims=(5, 5, 5))[0]["WI_1"]
    >>> w.type, w.open, w.head.tolist(), w.cells.tolist(), w.cell_open.tolist()
    ('water injector', True, [1, 2], [[1, 2, 3]], [True])
    """

    cache_size = 4

    def __init__(self, path, dims=None, nsteps: int | None = None):
        paths = [Path(p) for p in path] if isinstance(path, list | tuple) else [Path(path)]
        if not paths:
            raise InputError("restart wells: no restart file given")
        for p in paths:
            if not p.exists():
                raise InputError(f"{p}: no such file (the restart file of the wells)")
        self.path = paths[0]
        self.dims = None if dims is None else tuple(int(v) for v in dims)
        self._steps: list[_Step] = []
        self._cache: dict[int, SimWells] = {}
        self.damage: RecordError | None = None
        for p in paths:   # files, in report order
            if not self._scan(p, several=len(paths) > 1):
                break
        if nsteps is not None:
            del self._steps[int(nsteps):]
            for s in self._steps:   # the case's restart index kept only complete steps
                s.complete = True

    def _scan(self, p: Path, several: bool) -> bool:
        """Note the well records of each step of file ``p``; False after damage."""
        in_lgr = False
        first = len(self._steps)
        try:
            for rec in scan(p):   # headers only; stops at the first damaged record
                kw = rec.keyword
                if kw == "SEQNUM" or (several and len(self._steps) == first):
                    if len(self._steps) > first:
                        self._steps[-1].complete = True
                    m = _REPORT.search(p.name)
                    self._steps.append(_Step(int(m[1]) if m else len(self._steps), p))
                    in_lgr = False
                    if kw == "SEQNUM":
                        self._steps[-1].records["SEQNUM"] = rec
                        continue
                if len(self._steps) == first:
                    continue
                if kw == "LGR":
                    in_lgr = True
                elif kw == "ENDLGR":
                    in_lgr = False
                elif kw in _WELL_KEYWORDS and not in_lgr:
                    self._steps[-1].records.setdefault(kw, rec)
            if len(self._steps) > first:
                self._steps[-1].complete = True
        except RecordError as err:   # keep the complete steps before it (ecl.py warns)
            self.damage = err
            return False
        return True

    def __len__(self) -> int:
        return len(self._steps)

    def has_wells(self) -> bool:
        """True when some report step has an IWEL record with values (headers only)."""
        return any(s.records.get("IWEL") is not None and s.records["IWEL"].length > 0
                   for s in self._steps)

    def __getitem__(self, k: int) -> SimWells:
        n = len(self._steps)
        if not isinstance(k, int | np.integer) or not -n <= k < n:
            raise InputError(f"{self.path}: step {k} does not exist; the file has {n} report "
                             f"steps{f' (0-{n - 1})' if n else ''}")
        k = int(k) % n
        if k not in self._cache:
            while len(self._cache) >= self.cache_size:
                self._cache.pop(next(iter(self._cache)))
            self._cache[k] = self._read(k)
        return self._cache[k]

    def __iter__(self):
        return (self[k] for k in range(len(self)))

    # --- reading one step ----------------------------------------------------------------------
    def _array(self, k: int, kw: str, kinds: str) -> np.ndarray | None:
        rec = self._steps[k].records.get(kw)
        if rec is None:
            return None
        try:
            return rec.read(kinds)
        except RecordError as err:
            raise RecordError(f"{err} (report step {k})", err.offset, err.keyword,
                              err.after) from None

    def _fail(self, k: int, kw: str, what: str) -> InputError:
        return InputError(f"{self._steps[k].path}: {kw} (report step {k}): {what}")

    def _read(self, k: int) -> SimWells:
        step = self._steps[k]
        seq_arr = self._array(k, "SEQNUM", "i")
        seqnum = int(seq_arr[0]) if seq_arr is not None and seq_arr.size else step.seqnum
        if not step.complete:
            raise self._fail(k, "SEQNUM", f"the step is incomplete ({self.damage})")
        head = self._array(k, "INTEHEAD", "i")
        if head is None:
            raise self._fail(k, "INTEHEAD", "not found; expected one per report step")
        if head.size <= NICONZ:
            raise self._fail(k, "INTEHEAD", f"expected at least {NICONZ + 1} values, got "
                                            f"{head.size}")
        head = np.asarray(head, np.int64)
        date, (hh, mm, _) = step_time(head)
        if date and (hh or mm):  # an hourly step keeps its hour (as the grid's step dates)
            date += f" {hh:02d}:{mm:02d}"
        nw, ncw, niw, nzw, nic = (int(head[i]) for i in (NWELLS, NCWMAX, NIWELZ, NZWELZ,
                                                          NICONZ))
        out = SimWells(k, seqnum, date, (), str(step.path))
        if nw == 0:
            return out
        if not any(kw in step.records for kw in ("IWEL", "ZWEL", "ICON")):
            # OPM runs can list wells in INTEHEAD and write no well arrays (the Reek run)
            out.note = (f"INTEHEAD lists {nw} well{'s' if nw > 1 else ''} but the step has no "
                        "IWEL/ZWEL/ICON records")
            return out
        for name, v, least in (("NWELLS", nw, 0), ("NCWMAX", ncw, 0),
                               ("NIWELZ", niw, IWEL_STATUS + 1), ("NZWELZ", nzw, 1),
                               ("NICONZ", nic, ICON_STATUS + 1)):
            if v < least:
                raise self._fail(k, "INTEHEAD", f"{name} is {v}; expected at least {least}")
        iwel = self._sized(k, "IWEL", "i", nw * niw, f"NWELLS·NIWELZ = {nw}·{niw}")
        zwel = self._sized(k, "ZWEL", "S", nw * nzw, f"NWELLS·NZWELZ = {nw}·{nzw}")
        icon = (self._sized(k, "ICON", "i", nw * ncw * nic,
                            f"NWELLS·NCWMAX·NICONZ = {nw}·{ncw}·{nic}") if ncw
                else np.zeros(0, np.int64))
        iw = np.asarray(iwel, np.int64).reshape(nw, niw)
        ic = np.asarray(icon, np.int64).reshape(nw, ncw, nic)
        names = [_text(v) for v in np.asarray(zwel).reshape(nw, nzw)[:, 0]]
        nconn = iw[:, IWEL_NCONN]
        bad = np.flatnonzero((nconn < 0) | (nconn > ncw))
        if bad.size:
            w = int(bad[0])
            raise self._fail(k, "IWEL", f"well {names[w]} has {int(nconn[w])} connections; "
                                        f"expected 0..NCWMAX = {ncw}")
        # the used slots of every well, all wells at once
        used = (np.arange(ncw)[None, :] < nconn[:, None]) & (ic[:, :, ICON_SEQ] > 0)
        cells = ic[:, :, ICON_I:ICON_K + 1] - 1
        if self.dims is not None:
            nz = self.dims[2]
            frac = (cells[..., 2] >= nz) & (cells[..., 2] < 2 * nz)
            cells[..., 2] = np.where(frac, cells[..., 2] - nz, cells[..., 2])
            outside = used & np.any((cells < 0) | (cells >= np.array(self.dims)), axis=-1)
            if outside.any():
                w, c = (int(v) for v in np.argwhere(outside)[0])
                ijk = " ".join(str(int(v)) for v in ic[w, c, ICON_I:ICON_K + 1])
                raise self._fail(k, "ICON", f"well {names[w]} connection {c + 1} is in cell "
                                            f"I J K = {ijk}, outside the "
                                            f"{'×'.join(map(str, self.dims))} grid")
            heads = iw[:, [IWEL_HEAD_I, IWEL_HEAD_J]] - 1
            off = np.any((heads < 0) | (heads >= np.array(self.dims[:2])), axis=1)
            if off.any():
                w = int(np.flatnonzero(off)[0])
                raise self._fail(k, "IWEL", f"well {names[w]} has its head in column I J = "
                                            f"{heads[w, 0] + 1} {heads[w, 1] + 1}, outside the "
                                            f"{self.dims[0]}×{self.dims[1]} columns")
        cell_open = ic[:, :, ICON_STATUS] > 0
        wells = tuple(
            SimWell(names[w], WELL_TYPES.get(int(iw[w, IWEL_TYPE]), UNKNOWN_TYPE),
                    bool(iw[w, IWEL_STATUS] > 0), iw[w, [IWEL_HEAD_I, IWEL_HEAD_J]] - 1,
                    cells[w][used[w]], cell_open[w][used[w]])
            for w in range(nw))   # wells, not cells
        out.wells = wells
        return out

    def _sized(self, k: int, kw: str, kinds: str, want: int, what: str) -> np.ndarray:
        arr = self._array(k, kw, kinds)
        if arr is None:
            raise self._fail(k, kw, f"not found; INTEHEAD says the step has wells ({what})")
        if arr.size != want:
            raise self._fail(k, kw, f"expected {want} values ({what}), got {arr.size}")
        return arr


def _text(v: Any) -> str:
    return (v.decode("ascii", "replace") if isinstance(v, bytes) else str(v)).strip()


def restart_wells(grid) -> RestartWellIndex | None:
    """The simulation wells of a case loaded from its EGRID: a :class:`RestartWellIndex` over
    the case's UNRST (``grid.meta["unrst_path"]``), or its non-unified restart files
    (``grid.meta["restart"]["files"]`` when its ``kind`` is ``non-unified``), aligned with
    ``grid.steps``, made once and kept in ``grid.meta``; None when the case has no restart
    file.

    ``restart_wells(grid)[k]`` reads report step ``k``'s wells (IWEL/ICON/ZWEL only).
    """
    meta = grid.meta if isinstance(getattr(grid, "meta", None), dict) else None
    if meta is None:
        return None
    index = meta.get(META_KEY)
    if isinstance(index, RestartWellIndex):
        return index
    path = meta.get("unrst_path")
    restart = meta.get("restart") if isinstance(meta.get("restart"), dict) else {}
    if restart.get("kind") == "non-unified" and restart.get("files"):
        path = list(restart["files"])
    if not path:
        return None
    nsteps = len(meta.get("unrst_seqnum") or grid.steps or []) or None
    index = RestartWellIndex(path, grid.dims, nsteps)
    meta[META_KEY] = index
    return index


def has_restart_wells(grid) -> bool:
    """True when the case's restart file has wells at some report step (headers only)."""
    index = restart_wells(grid)
    return index is not None and index.has_wells()


def describe_restart_wells(grid) -> dict | None:
    """The simulation wells of a case for ``geoshade info``; None when the case has no restart
    file.

    Keys: ``wells``: one dict per well, in order of first appearance, with ``name``, ``type``,
    ``first_step`` and ``last_step`` (indices of the report steps it is in), and at its last
    step ``open``, ``completions`` and ``open_completions``; ``note``: what the file lacks
    ("" when nothing), e.g. wells listed in INTEHEAD without IWEL/ICON/ZWEL records.

    Reads the well records of every report step (a few hundred bytes per well and step).
    """
    index = restart_wells(grid)
    if index is None:
        return None
    out: dict[str, dict] = {}
    note = ""
    for k in range(len(index)):  # report steps
        step = index[k]
        note = note or step.note
        for w in step:
            d = out.setdefault(w.name, {"name": w.name, "first_step": k})
            d.update(type=w.type, last_step=k, open=w.open, completions=len(w.cells),
                     open_completions=int(np.count_nonzero(w.cell_open)))
    return {"wells": list(out.values()), "note": note}


def format_restart_wells(d: dict | None) -> list[str]:
    """Lines of ``geoshade info`` for :func:`describe_restart_wells` (none for None).

    >>> format_restart_wells({"note": "", "wells": [{"name": "OP_1", "type": "producer",
    ...     "first_step": 1, "last_step": 36, "open": True, "completions": 14,
    ...     "open_completions": 12}]})
    ['  sim wells 1 in the restart file:', '    OP_1  producer, open at step 36, 12 of 14 \
completions open (steps 1..36)']
    """
    if d is None:
        return []
    wells = d.get("wells") or []
    if not wells:
        return [f"  sim wells none in the restart file{': ' + d['note'] if d.get('note') else ''}"]
    lines = [f"  sim wells {len(wells)} in the restart file:"]
    for w in wells:
        lines.append(f"    {w['name']}  {w['type']}, {'open' if w['open'] else 'shut'} at step "
                     f"{w['last_step']}, {w['open_completions']} of {w['completions']} "
                     f"completions open (steps {w['first_step']}..{w['last_step']})")
    return lines


__all__ = ["RestartWellIndex", "describe_restart_wells", "format_restart_wells",
           "has_restart_wells", "restart_wells"]
