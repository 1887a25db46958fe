"""Wells of a simulation (restart files) and well trajectories with measured depth.

:class:`SimWell` is one well at one report step as the simulator wrote it (IWEL/ICON/ZWEL of
an UNRST): name, type, open or shut, well-head column and the completion cells with their own
open/shut state. :class:`SimWells` is the set of wells of one report step.
:class:`Trajectory` is a :class:`~geoshade.models.grid.WellPath` that also carries measured
depths (read from RMS ASCII well files and CSV trajectories).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from geoshade.errors import InputError
from geoshade.models import reprs
from geoshade.models.grid import WellPath
from geoshade.models.reprs import num, points_text

#: the IWEL well-type codes (ECLIPSE/OPM): 1 producer, 2 oil, 3 water, 4 gas injector
WELL_TYPES = {1: "producer", 2: "oil injector", 3: "water injector", 4: "gas injector"}
#: the type of a code not in :data:`WELL_TYPES` (0 appears for wells never controlled)
UNKNOWN_TYPE = "unknown"



def _checked_completions(name: str, kind: str, cell_open, n: int) -> np.ndarray:
    """``cell_open`` as ``(n,) bool`` (one per completion) and ``kind`` one of the well types,
    or one line naming the well (restart and deck wells alike)."""
    cell_open = np.asarray(cell_open, bool).reshape(-1)
    if len(cell_open) != n:
        raise InputError(f"well {name}: cell_open: expected {n} values (one per completion), "
                         f"got {len(cell_open)}")
    if kind not in (*WELL_TYPES.values(), UNKNOWN_TYPE):
        raise InputError(f"well {name}: type: expected one of "
                         f"{', '.join([*WELL_TYPES.values(), UNKNOWN_TYPE])}, got {kind!r}")
    return cell_open

@dataclass
class SimWell:
    """One simulation well at one report step.

    name:      str                well name (ZWEL)
    type:      str                ``producer``, ``water injector``, ``gas injector``,
                                  ``oil injector`` or ``unknown``
    open:      bool               the well is open (IWEL status > 0)
    head:      (2,) int64         well-head column i, j (0-based)
    cells:     (n, 3) int64       completion cells i, j, k (0-based), in the file's order
    cell_open: (n,) bool          each completion open (ICON status > 0)

    Examples
    --------
    >>> w = SimWell("OP_1", "producer", True, (4, 5), [[4, 5, 0], [4, 5, 1]], [True, False])
    >>> w.cells.shape, int(w.cell_open.sum()), w.injector
    ((2, 3), 1, False)
    """

    name: str
    type: str
    open: bool
    head: np.ndarray
    cells: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.int64))
    cell_open: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))

    def __post_init__(self) -> None:
        self.head = np.asarray(self.head, np.int64).reshape(2)
        self.cells = np.asarray(self.cells, np.int64).reshape(-1, 3)
        self.cell_open = _checked_completions(self.name, self.type, self.cell_open,
                                              len(self.cells))

    @property
    def injector(self) -> bool:
        return self.type.endswith("injector")

    def __repr__(self) -> str:
        """``SimWell('OP_1', producer, open, head (4, 5), 2 completions (1 open))``."""
        return (f"SimWell({self.name!r}, {self.type}, {'open' if self.open else 'shut'}, head "
                f"({int(self.head[0])}, {int(self.head[1])}), {len(self.cells)} completions "
                f"({int(self.cell_open.sum())} open))")


@dataclass(repr=False)
class SimWells:
    """The wells of one report step of a restart file.

    step:   int          index of the report step (as ``grid.steps``)
    seqnum: int          the file's report number (SEQNUM)
    date:   str          ISO date ("" where unknown)
    wells:  tuple of :class:`SimWell`, in the file's order
    source: str          the file, for messages
    note:   str          what the step lacks ("" when nothing), e.g. wells listed in INTEHEAD
                         without well records
    """

    step: int
    seqnum: int
    date: str
    wells: tuple = ()
    source: str = ""
    note: str = ""

    def __len__(self) -> int:
        return len(self.wells)

    def __iter__(self):
        return iter(self.wells)

    def names(self) -> list[str]:
        return [w.name for w in self.wells]

    def __getitem__(self, name: str) -> SimWell:
        """The well called ``name`` (exact, else case-insensitive)."""
        for w in self.wells:
            if w.name == name:
                return w
        for w in self.wells:
            if w.name.upper() == str(name).upper():
                return w
        raise KeyError(name)

    @property
    def completions(self) -> int:
        return int(sum(len(w.cells) for w in self.wells))

    def __repr__(self) -> str:
        """The step, counts by type and state, and the names (like xarray's repr).

        >>> print(SimWells(2, 3, "2000-03-01", (SimWell("P", "producer", True, (0, 0)),)))
        <SimWells step 2 (report 3, 2000-03-01)>
        Wells:        1 (1 open): P
        Types:        1 producer
        Completions:  0 (0 open)
        """
        when = ", ".join(t for t in (f"report {self.seqnum}", self.date) if t)
        types = Counter(w.type for w in self.wells)
        n_open = sum(int(w.cell_open.sum()) if w.open else 0 for w in self.wells)
        head = f"<SimWells step {self.step} ({when})>"
        body = reprs.block("", "", [
            ("Wells", f"{len(self)} ({sum(bool(w.open) for w in self.wells)} open)"
                      + (f": {reprs.names(self.names())}" if len(self) else "")),
            ("Types", ", ".join(f"{n} {t}" for t, n in types.items())),
            ("Completions", f"{reprs.count(self.completions)} ({reprs.count(n_open)} open)"),
            ("Source", self.source), ("Note", self.note)])
        return head + body[len("<>"):]


@dataclass(repr=False)
class DeckWell(WellPath):
    """A :class:`~geoshade.models.grid.WellPath` of a deck's schedule (WELSPECS/COMPDAT),
    drawn as restart wells are: a named pipe from above its head column through its
    completions, in its type's colour.

    type:      str        as :attr:`SimWell.type`: from WCONPROD/WCONHIST (producer) or
                          WCONINJE/WCONINJH (its phase's injector); ``unknown`` when the deck
                          has no control record for the well
    cell_open: (m,) bool  each completion (marker) open: the last COMPDAT state of its cell

    >>> w = DeckWell("WI_1", [[0, 0, 900], [0, 0, 1000]], [[0, 0, 1000]], [[0, 0, 3]],
    ...              type="water injector")
    >>> w.cell_open.tolist(), w.injector
    ([True], True)
    """

    type: str = UNKNOWN_TYPE
    cell_open: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        m = len(self.markers)
        self.cell_open = _checked_completions(
            self.name, self.type, np.ones(m, bool) if self.cell_open is None else self.cell_open,
            m)

    @property
    def injector(self) -> bool:
        return self.type.endswith("injector")

    def __repr__(self) -> str:
        """``DeckWell('WI_1', water injector, 2 points, ..., 1 completions (1 open))``."""

        n_open = int(np.count_nonzero(np.asarray(self.cell_open)))
        return (f"DeckWell({self.name!r}, {self.type}, {points_text(self.points)}, "
                f"{len(self.cells)} completions ({n_open} open))")


def well_type(well) -> str:
    """The type of any well model: a :class:`SimWell`'s or :class:`DeckWell`'s own,
    ``unknown`` for a trajectory (files do not say).

    >>> well_type(Trajectory("A", [[0, 0, 1]])), well_type(DeckWell("B", [[0, 0, 1]],
    ...                                                   type="producer"))
    ('unknown', 'producer')
    """
    return str(getattr(well, "type", UNKNOWN_TYPE) or UNKNOWN_TYPE)


#: what WCONINJE/WCONINJH's injected phase (its first three letters) makes of a well
INJECTED = {"WAT": "water injector", "GAS": "gas injector", "OIL": "oil injector"}


@dataclass(repr=False)
class Trajectory(WellPath):
    """A :class:`~geoshade.models.grid.WellPath` with measured depths.

    md: (n,) float  measured depth of each trajectory point (NaN where the file had none)

    >>> t = Trajectory("A", [[0, 0, 1000], [0, 0, 1100]], md=[1000, 1100])
    >>> t.md.tolist(), Trajectory("B", [[0, 0, 0]]).md.tolist()
    ([1000.0, 1100.0], [nan])
    """

    md: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        n = len(self.points)
        self.md = (np.full(n, np.nan) if self.md is None
                   else np.asarray(self.md, float).reshape(-1))
        if len(self.md) != n:
            raise InputError(f"well {self.name}: md: expected {n} values (one per point), got "
                             f"{len(self.md)}")


    def __repr__(self) -> str:
        """``Trajectory('A', 2 points, ..., md 1000–1100)``."""

        md = np.asarray([] if self.md is None else self.md, float)
        md = md[np.isfinite(md)]
        mdt = f", md {num(md.min())}–{num(md.max())}" if len(md) else ""
        return f"Trajectory({self.name!r}, {points_text(self.points)}{mdt})"


__all__ = ["INJECTED", "UNKNOWN_TYPE", "WELL_TYPES", "DeckWell", "SimWell", "SimWells",
           "Trajectory", "well_type"]
