"""ECLIPSE/OPM input decks (``.DATA``): grid, properties, faults and wells through the INCLUDEs.

The deck is streamed with the GRDECL reader (:mod:`geoshade.io.grids.grdecl`; it applies ``EQUALS``,
``MULTIPLY``, ``ADD``, ``COPY``, ``MINVALUE``, ``MAXVALUE``, each with an optional ``I1 I2 J1 J2
K1 K2`` box defaulting to the current BOX), which this module extends with:

- sections (RUNSPEC, GRID, ...: no cell arrays are looked for in RUNSPEC, SUMMARY, SCHEDULE);
- ``PATHS`` aliases for ``INCLUDE '$ALIAS/file'`` (an unknown alias falls back to an
  environment variable, then to the path without it, relative to the including file and then to
  the deck);
- ``WELSPECS`` (well heads) and ``COMPDAT`` (completions), giving ``grid.meta["wells"]``: one
  :class:`~geoshade.models.wells.DeckWell` per well, a pipe from the top of its head column
  through its completion cells' centres (in COMPDAT order, as restart wells are drawn), with a
  marker at each completion cell and each completion's last OPEN/SHUT state;
- ``WCONPROD``/``WCONHIST`` (producers) and ``WCONINJE``/``WCONINJH`` (injectors of the
  named phase) give each well its type (``unknown`` without a control record).

Block-centred geometry and the edit keywords on it (``EQUALS 'TOPS' 8325 1 10 1 10 1 1 /``),
missing INCLUDEs (``skip_missing``) and the unit system (METRIC unless RUNSPEC says FIELD, LAB
or PVT-M) are as in :mod:`geoshade.io.grids.grdecl`.

Everything else in RUNSPEC, PROPS tables, SOLUTION, SUMMARY and SCHEDULE is skipped record by
record (never read whole); one warning lists the keywords that were not used.
"""

from __future__ import annotations

import fnmatch
import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.grdecl import GridBuilder, _Source
from geoshade.models import CornerPointGrid
from geoshade.models.wells import INJECTED, UNKNOWN_TYPE, DeckWell

_SECTIONS = frozenset({"RUNSPEC", "GRID", "EDIT", "PROPS", "REGIONS", "SOLUTION", "SUMMARY",
                       "SCHEDULE"})
#: sections without cell arrays: unknown keywords there are skipped without a numeric scan
_NO_ARRAYS = frozenset({"RUNSPEC", "SUMMARY", "SCHEDULE"})

def match_wells(pattern: str, names) -> list[str]:
    """Well names matching an ECLIPSE well name or pattern (``*`` and ``?`` wildcards).

    Examples
    --------
    >>> match_wells("OP*", ["OP_1", "WI_1", "OP_2"])
    ['OP_1', 'OP_2']
    """
    return [n for n in names if fnmatch.fnmatchcase(n, pattern)]


def _centres(grid: CornerPointGrid, cells: np.ndarray) -> np.ndarray:
    """(m, 3) centres (mean of the 8 corners) of cells (m, 3); the same arithmetic as
    ``geoshade.compute.grid.geometry.cell_centres`` (io may not import compute)."""
    i, j, k = (cells[:, q].astype(np.int64) for q in range(3))
    acc = np.zeros((len(cells), 3))
    for c in range(8):
        a, b, cc = c & 1, c >> 1 & 1, c >> 2 & 1
        acc += _on_pillar(np.asarray(grid.coord)[i + a, j + b],
                          np.asarray(grid.zcorn[2 * i + a, 2 * j + b, 2 * k + cc], np.float64))
    return acc / 8.0


def _on_pillar(pil: np.ndarray, z: np.ndarray) -> np.ndarray:
    dz = pil[:, 5] - pil[:, 2]
    t = np.where(dz != 0, (z - pil[:, 2]) / np.where(dz != 0, dz, 1.0), 0.0)
    return np.stack([pil[:, 0] + t * (pil[:, 3] - pil[:, 0]),
                     pil[:, 1] + t * (pil[:, 4] - pil[:, 1]), z], 1)


class DeckBuilder(GridBuilder):
    """:class:`GridBuilder` plus sections, PATHS, WELSPECS and COMPDAT."""

    def __init__(self, path: Path, progress=None, skip_missing: bool = False):
        super().__init__(path, progress, skip_missing)
        self.meta["format"] = "DATA deck"
        self.section = ""
        self.heads: dict[str, tuple[int, int]] = {}
        #: well -> (i, j, k) -> the completion is open (the last COMPDAT record of the cell)
        self.completions: dict[str, dict[tuple[int, int, int], bool]] = {}
        self.no_welspecs: dict[str, list[str]] = {}  # file -> COMPDAT wells skipped (one warning)
        self.types: dict[str, str] = {}
        self.handlers.update(PATHS=self._paths, WELSPECS=self._welspecs, COMPDAT=self._compdat,
                             WCONPROD=self._producer, WCONHIST=self._producer,
                             WCONINJE=self._injector, WCONINJH=self._injector)

    def keyword(self, kw: str, src: _Source) -> None:
        if kw in _SECTIONS:
            self.section = kw
        super().keyword(kw, src)

    def unknown(self, kw: str, src: _Source) -> None:
        if self.section not in _NO_ARRAYS:
            return super().unknown(kw, src)
        kind, _, bol, _ = src.peek()
        self.skip(kw, src)
        if kind in ("", "w") and (kind == "" or bol):
            return None
        src.skip_record()
        return None

    def finish(self) -> CornerPointGrid:
        self.unit_system = self.unit_system or "METRIC"  # ECLIPSE's default
        return super().finish()

    def warn_skipped(self) -> None:
        if self.skipped:
            names = list(self.skipped)
            more = f" and {len(names) - 30} more" if len(names) > 30 else ""
            warnings.warn(f"{self.root}: {len(names)} keywords not used by the grid reader were "
                          f"skipped: {', '.join(names[:30])}{more}", stacklevel=3)
        for path, wells in self.no_welspecs.items():  # one line per file, however many records
            shown = ", ".join(repr(w) for w in wells[:10])
            more = f" and {len(wells) - 10} more" if len(wells) > 10 else ""
            warnings.warn(f"{path}: COMPDAT: {len(wells)} record(s) name a well with no WELSPECS "
                          f"before ({shown}{more}); skipped", stacklevel=3)

    def _paths(self, kw, src):
        while True:
            rec = src.record(kw)
            if not rec:
                return
            if len(rec) >= 2 and rec[0] and rec[1]:
                self.aliases[str(rec[0]).upper()] = str(rec[1])

    # -- wells ----------------------------------------------------------------------------
    def _int(self, v, kw, what, src) -> int | None:
        if v is None:
            return None
        try:
            return int(v)
        except ValueError:
            raise InputError(f"{src.path}: {kw}: {what} must be an integer, got {v!r}") from None

    def _welspecs(self, kw, src):
        while True:
            rec = src.record(kw)
            if not rec:
                return
            name = str(rec[0]).strip() if rec[0] else ""
            i = self._int(rec[2] if len(rec) > 2 else None, kw, f"{name} I", src)
            j = self._int(rec[3] if len(rec) > 3 else None, kw, f"{name} J", src)
            if not name or i is None or j is None:
                raise InputError(f"{src.path}: WELSPECS: expected NAME GROUP I J ..., got "
                                 f"{' '.join(map(str, rec))!r}")
            self.heads[name] = (i - 1, j - 1)
            self.completions.setdefault(name, {})

    def _compdat(self, kw, src):
        while True:
            rec = src.record(kw)
            if not rec:
                return
            rec = [*rec, *[None] * 5]
            pattern = str(rec[0]).strip() if rec[0] else ""
            names = match_wells(pattern, self.heads)
            if not names:
                self.no_welspecs.setdefault(str(src.path), []).append(pattern)
                continue
            vals = [self._int(v, kw, f"{pattern} {w}", src)
                    for v, w in zip(rec[1:5], ("I", "J", "K1", "K2"), strict=True)]
            for name in names:
                hi, hj = self.heads[name]
                i = hi if not vals[0] else vals[0] - 1
                j = hj if not vals[1] else vals[1] - 1
                if vals[2] is None or vals[3] is None:
                    raise InputError(f"{src.path}: COMPDAT {name}: expected K1 and K2, got "
                                     f"{rec[3]!r} {rec[4]!r}")
                nz = self.dims[2] if self.dims is not None else 1 << 20
                if vals[3] - vals[2] >= nz:  # more layers than the grid has (a cell outside
                    # it is reported in wells())
                    raise InputError(f"{src.path}: COMPDAT {name}: layers K1-K2 {vals[2]}-"
                                     f"{vals[3]} span more layers than the grid's {nz}")
                state = str(rec[5] or "OPEN").strip().upper()
                cells = self.completions[name]
                for k in range(vals[2] - 1, vals[3]):  # the layers of one completion record
                    cells[(i, j, k)] = state != "SHUT"  # a later record keeps its place

    def _producer(self, kw, src):
        """WCONPROD / WCONHIST: the matching wells are producers."""
        while True:
            rec = src.record(kw)
            if not rec:
                return
            for name in match_wells(str(rec[0] or "").strip(), self.heads):
                self.types[name] = "producer"

    def _injector(self, kw, src):
        """WCONINJE / WCONINJH: the matching wells inject the phase of item 2."""
        while True:
            rec = src.record(kw)
            if not rec:
                return
            phase = str(rec[1] if len(rec) > 1 and rec[1] else "").strip().upper()
            kind = INJECTED.get(phase[:3], UNKNOWN_TYPE)
            for name in match_wells(str(rec[0] or "").strip(), self.heads):
                self.types[name] = kind

    def wells(self, grid: CornerPointGrid) -> list[DeckWell]:
        """A :class:`~geoshade.models.wells.DeckWell` per WELSPECS well: from the top of its
        head column through the centres of its completion cells in COMPDAT order (a well
        without completions: down its head column), markers at the completion cells (0-based
        i, j, k), its type from the control keywords and each completion's last state."""
        nx, ny, nz = grid.dims
        out = []
        for name, (hi, hj) in self.heads.items():
            comp = self.completions.get(name, {})
            cells = np.array(list(comp), np.int64).reshape(-1, 3)
            bad = (cells < 0).any(axis=1) | (cells >= (nx, ny, nz)).any(axis=1)
            if not (0 <= hi < nx and 0 <= hj < ny) or bad.any():
                where = tuple(int(v) + 1 for v in (cells[bad][0] if bad.any() else (hi, hj)))
                raise InputError(f"{self.root}: well {name}: cell {where} is outside the grid "
                                 f"{grid.dims}")
            col = np.stack([np.full(nz, hi), np.full(nz, hj), np.arange(nz)], 1)
            a, b = np.array([0, 1, 0, 1]), np.array([0, 0, 1, 1])  # the 4 top corners
            top = _on_pillar(np.asarray(grid.coord)[hi + a, hj + b],
                             np.asarray(grid.zcorn[2 * hi + a, 2 * hj + b, 0], np.float64))
            markers = _centres(grid, cells) if len(cells) else np.zeros((0, 3))
            pts = np.concatenate([top.mean(axis=0, keepdims=True),
                                  markers if len(cells) else _centres(grid, col)])
            out.append(DeckWell(name, pts, markers, cells,
                                type=self.types.get(name, UNKNOWN_TYPE),
                                cell_open=np.array(list(comp.values()), bool)))
        return out


def read_deck(path, progress=None, skip_missing: bool = False) -> CornerPointGrid:
    """Read an ECLIPSE/OPM ``.DATA`` deck: its grid, properties, faults and wells.

    Parameters
    ----------
    path : str or Path
        The deck; INCLUDEs are followed (relative to the including file, then to the deck;
        quoted names and ``'$ALIAS/...'`` paths).
    progress : callable, optional
        ``progress(bytes_read, bytes_total)``, as for :func:`geoshade.io.grids.grdecl.read_grdecl`.
    skip_missing : bool
        Read what is there when INCLUDE files are missing, as for
        :func:`geoshade.io.grids.grdecl.read_grdecl` (a grid without geometry: IJK index space).

    Returns
    -------
    CornerPointGrid
        As from the GRDECL reader (block-centred geometry too), with the edit keywords applied
        (also to DX, DY, DZ, TOPS), ``meta["format"]`` "DATA deck", ``meta["unit_system"]``
        (METRIC, FIELD, LAB or PVT-M; METRIC where RUNSPEC names none, as in ECLIPSE) and
        ``meta["wells"]`` a list of :class:`~geoshade.models.wells.DeckWell` (named pipes
        through their completions, typed by WCONPROD/WCONHIST/WCONINJE/WCONINJH).

    Raises
    ------
    InputError
        As the GRDECL reader (missing INCLUDEs: all of them in one line); also a
        WELSPECS/COMPDAT record that cannot be read, or a completion outside the grid.

    Examples
    --------
    >>> import os, tempfile, warnings
    >>> d = tempfile.mkdtemp()
    >>> _ = open(os.path.join(d, "g.inc"), "w").write(
    ...     "COORD 0 0 0 0 0 9 1 0 0 1 0 9 0 1 0 0 1 9 1 1 0 1 1 9 /\\n"
    ...     "ZCORN 4*0 8*1 4*2 /\\nPORO 2*0.2 /\\n")
    >>> _ = open(os.path.join(d, "C.DATA"), "w").write(
    ...     "RUNSPEC\\nDIMENS\\n 1 1 2 /\\nGRID\\nINCLUDE\\n 'g.inc' /\\n"
    ...     "MULTIPLY\\n PORO 2 /\\n/\\n"
    ...     "SCHEDULE\\nWELSPECS\\n 'W1' 'G' 1 1 1* OIL /\\n/\\n"
    ...     "COMPDAT\\n 'W1' 2* 2 2 OPEN /\\n/\\nEND\\n")
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     g = read_deck(os.path.join(d, "C.DATA"))
    >>> g.dims, float(g.properties["PORO"][0, 0, 1]), g.meta["wells"][0].cells.tolist()
    ((1, 1, 2), 0.4000000059604645, [[0, 0, 1]])
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    builder = DeckBuilder(p, progress, skip_missing)
    builder.parse_all()
    builder.warn_skipped()
    grid = builder.finish()
    grid.meta["wells"] = builder.wells(grid)
    return grid
