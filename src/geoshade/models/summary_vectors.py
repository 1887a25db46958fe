"""Summary vectors of a simulation run: rates, pressures, totals over time (ECLIPSE/OPM SMSPEC).

A :class:`SummaryTable` holds the values of some vectors at every ministep of a run, as the
simulator wrote them (``PARAMS`` records, float32 as read), with the time of each ministep, the
report step it belongs to, and each vector's ECLIPSE name, kind and unit. It needs neither pandas
nor xarray: :meth:`SummaryTable.to_pandas` (the ``parquet`` extra) and
:meth:`SummaryTable.to_xarray` (the ``netcdf`` extra) convert it when asked.

Vector names are ECLIPSE's (as resdata and ResInsight write them): ``FOPR`` (field),
``WBHP:PROD`` (well), ``GOPR:OP`` (group), ``RPR:3`` (region), ``ROFT:1-2`` (flow between two
regions), ``BPR:15,28,1`` (block, 1-based i,j,k), ``COPR:PROD:1,2,3`` (connection),
``SOFR:PROD:4`` (segment), ``AAQR:1`` (aquifer), ``NPR:NODE`` (network node), ``LBPR:LGR1:2,2,3``
(a local grid's block), ``TIME`` (the others).

>>> import numpy as np, datetime
>>> t = SummaryTable(np.array([1.0, 31.0]), np.array([[10, 200], [12, 190]], np.float32),
...                  [SummaryVector("FOPR", "FOPR", "field", "SM3/DAY"),
...                   SummaryVector("WBHP:P1", "WBHP", "well", "BARSA", name="P1")],
...                  datetime.datetime(2000, 1, 1), report=np.array([1, 2]))
>>> t.keys, t["WBHP:P1"].tolist(), t.dates[1]
(('FOPR', 'WBHP:P1'), [200.0, 190.0], np.datetime64('2000-02-01T00:00:00'))
>>> match_vectors(t.keys, ["W*"])
['WBHP:P1']
"""

from __future__ import annotations

import datetime
import difflib
import fnmatch
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from geoshade.errors import InputError, require
from geoshade.models import reprs

#: the kinds of vector, from the keyword's first letter (ECLIPSE's variable types)
KINDS = ("field", "well", "group", "region", "region-flow", "block", "connection", "segment",
         "aquifer", "network", "local-block", "local-connection", "local-well", "misc")
#: the unit systems of SMSPEC's INTEHEAD item 1
UNIT_SYSTEMS = {1: "METRIC", 2: "FIELD", 3: "LAB", 4: "PVT-M"}


@dataclass(frozen=True)
class SummaryVector:
    """One summary vector.

    key:     str          its ECLIPSE name (``WBHP:PROD``, ``BPR:1,2,3``, ``FOPR``)
    keyword: str          the SMSPEC keyword (``WBHP``)
    kind:    str          one of :data:`KINDS`
    unit:    str          SMSPEC's UNITS entry (``BARSA``, ``STB/DAY``; "" dimensionless)
    name:    str          the well, group or node it belongs to ("" for others)
    num:     int          SMSPEC's NUMS entry (region, block, segment, aquifer number; 0 if none)
    ijk:     tuple or None  1-based (i, j, k) of a block or connection
    index:   int          its position in a PARAMS record (-1 where unknown)
    """

    key: str
    keyword: str
    kind: str
    unit: str = ""
    name: str = ""
    num: int = 0
    ijk: tuple[int, int, int] | None = None
    index: int = -1

    def unit_label(self) -> str:
        """The unit for an axis: SMSPEC's text, or ``dimensionless`` where it is empty.

        >>> SummaryVector("FWCT", "FWCT", "field").unit_label()
        'dimensionless'
        """
        return self.unit or "dimensionless"


def match_vectors(keys: Sequence[str], patterns: Iterable[str], where: str = "") -> list[str]:
    """The keys ``patterns`` name, in the order given, each once.

    A pattern is a name (``WBHP:PROD``; exact first, then in any case) or a shell wildcard
    (``WOPR:*``, ``BPR:*``, ``F?PR``) that expands to every matching name in table order. A name
    or a wildcard that matches nothing is one line naming it and the nearest names.

    Examples
    --------
    >>> keys = ["FOPR", "WOPR:P1", "WOPR:P2", "WBHP:P1"]
    >>> match_vectors(keys, ["wbhp:p1", "WOPR:*", "WOPR:P1"])
    ['WBHP:P1', 'WOPR:P1', 'WOPR:P2']
    >>> match_vectors(keys, ["WOPT:P1"], "CASE.SMSPEC")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: CASE.SMSPEC: no summary vector WOPT:P1; nearest: WOPR:P1, ...
    """
    by_upper: dict[str, str] = {}
    for k in keys:
        by_upper.setdefault(k.upper(), k)
    out: dict[str, None] = {}
    w = f"{where}: " if where else ""
    for pat in patterns:
        pat = str(pat).strip()
        if pat in by_upper.values():
            out[pat] = None
            continue
        if pat.upper() in by_upper:
            out[by_upper[pat.upper()]] = None
            continue
        if any(c in pat for c in "*?["):
            found = [k for k in keys if fnmatch.fnmatchcase(k.upper(), pat.upper())]
            if found:
                out.update(dict.fromkeys(found))
                continue
            raise InputError(f"{w}no summary vector matches {pat}{_nearest(keys, pat)}")
        raise InputError(f"{w}no summary vector {pat}{_nearest(keys, pat)}")
    return list(out)


def _nearest(keys: Sequence[str], pat: str) -> str:
    """``; nearest: A, B, C`` (difflib), else where to look."""
    probe = pat.upper().replace("*", "").replace("?", "")
    upper = {k.upper(): k for k in keys}
    near = difflib.get_close_matches(probe, list(upper), n=5, cutoff=0.5)
    if not near and ":" in probe:  # the keyword alone: WOPT:P9 -> WOPT:... of other wells
        head = probe.split(":", 1)[0] + ":"
        near = [u for u in upper if u.startswith(head)][:5]
    if near:
        return "; nearest: " + ", ".join(upper[n] for n in near)
    return f"; {len(keys)} vectors (geoshade summary CASE --list lists them)"


@dataclass
class SummaryTable:
    """Summary vectors at every ministep of a run.

    days:     (n,) float64       simulated time of each ministep, days since ``start``
    values:   (n, m) float32|64  each vector's value at each ministep (as the file stores it)
    vectors:  m SummaryVector    what each column is (key, kind, unit ...), keys unique
    start:    datetime           the run's start (SMSPEC STARTDAT)
    report:   (n,) int32         the report step each ministep belongs to (1 = the first; the
                                 last ministep of a report step is at that report's date);
                                 default: each ministep its own report step
    ministep: (n,) int32         the simulator's ministep numbers (default 1..n)
    unit_system: str             ``METRIC``, ``FIELD``, ``LAB``, ``PVT-M`` or ""
    name:     str                the file it came from, for messages
    meta:     dict               what the reader knew (files, format, skipped entries)

    Examples
    --------
    >>> import numpy as np, datetime
    >>> t = SummaryTable(np.array([0.5, 1.0, 2.0]), np.ones((3, 1), np.float32),
    ...                  [SummaryVector("FPR", "FPR", "field", "PSIA")],
    ...                  datetime.datetime(2015, 1, 1), report=np.array([1, 1, 2]))
    >>> t.nsteps, t.report_index().tolist(), t.iso_dates()[0]
    (3, [1, 2], '2015-01-01T12:00:00')
    """

    days: np.ndarray
    values: np.ndarray
    vectors: Sequence[SummaryVector]
    start: datetime.datetime
    report: np.ndarray | None = None
    ministep: np.ndarray | None = None
    unit_system: str = ""
    name: str = ""
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        w = f"{self.name}: " if self.name else ""
        self.days = np.asarray(self.days, np.float64)
        if self.days.ndim != 1:
            raise InputError(f"{w}days: expected shape (n,), got {self.days.shape}")
        n = self.days.size
        self.values = np.asarray(self.values)
        self.vectors = tuple(self.vectors)
        m = len(self.vectors)
        if self.values.shape != (n, m):
            raise InputError(f"{w}values: expected shape (n, m) = ({n}, {m}) (ministeps, "
                             f"vectors), got {self.values.shape}")
        if self.values.dtype.kind != "f":
            raise InputError(f"{w}values: expected float32 or float64, got {self.values.dtype}")
        if not all(isinstance(v, SummaryVector) for v in self.vectors):
            raise InputError(f"{w}vectors: expected SummaryVector entries")
        keys = [v.key for v in self.vectors]
        if len(set(keys)) != m:
            dup = sorted({k for k in keys if keys.count(k) > 1})
            raise InputError(f"{w}vectors: names must be unique, {', '.join(dup)} repeated")
        if not np.all(np.isfinite(self.days)) or np.any(np.diff(self.days) < 0):
            raise InputError(f"{w}days: expected finite times that never decrease")
        self.report = _int_array(self.report, np.arange(1, n + 1), n, "report", w)
        self.ministep = _int_array(self.ministep, np.arange(1, n + 1), n, "ministep", w)
        if not isinstance(self.start, datetime.datetime):
            raise InputError(f"{w}start: expected a datetime, got {type(self.start).__name__}")
        self._column = {k: i for i, k in enumerate(keys)}

    # --- names ---------------------------------------------------------------------------------
    @property
    def keys(self) -> tuple[str, ...]:
        """The vectors' names, in column order."""
        return tuple(v.key for v in self.vectors)

    @property
    def nsteps(self) -> int:
        """Number of ministeps (rows)."""
        return int(self.days.size)

    def vector(self, key: str) -> SummaryVector:
        """The :class:`SummaryVector` named ``key`` (any case); one line with the nearest names
        if there is none."""
        return self.vectors[self._column[match_vectors(self.keys, [key], self.name)[0]]]

    def __getitem__(self, key: str) -> np.ndarray:
        """The values of vector ``key`` at every ministep, ``(n,)``."""
        return self.values[:, self._column[self.vector(key).key]]

    def __contains__(self, key: object) -> bool:
        return isinstance(key, str) and key.upper() in {k.upper() for k in self.keys}

    def units(self) -> dict[str, str]:
        """``{key: unit}`` of every vector (SMSPEC's text, "" dimensionless)."""
        return {v.key: v.unit for v in self.vectors}

    def select(self, patterns: Iterable[str], where: str = "") -> SummaryTable:
        """A table of the vectors ``patterns`` name (see :func:`match_vectors`), in that order.

        >>> import numpy as np, datetime
        >>> t = SummaryTable([1.0], np.zeros((1, 2), np.float32),
        ...                  [SummaryVector("FOPR", "FOPR", "field"),
        ...                   SummaryVector("FPR", "FPR", "field")], datetime.datetime(2000, 1, 1))
        >>> t.select(["FPR"]).keys
        ('FPR',)
        """
        keys = match_vectors(self.keys, patterns, where or self.name)
        cols = [self._column[k] for k in keys]
        return SummaryTable(self.days, self.values[:, cols], [self.vectors[c] for c in cols],
                            self.start, self.report, self.ministep, self.unit_system, self.name,
                            dict(self.meta))

    # --- time ----------------------------------------------------------------------------------
    @property
    def dates(self) -> np.ndarray:
        """``(n,) datetime64[s]``: the date and time of each ministep (``start + days``, to the
        second)."""
        seconds = np.round(self.days * 86400.0).astype(np.int64).astype("timedelta64[s]")
        return np.datetime64(self.start, "s") + seconds

    def iso_dates(self) -> list[str]:
        """Each ministep's date and time as ISO text (``2015-01-01T06:00:00``)."""
        return [str(d) for d in self.dates]

    def report_index(self) -> np.ndarray:
        """``(R,) int``: the row of each report step's end (its last ministep), in order."""
        if not self.nsteps:
            return np.zeros(0, np.int64)
        last = np.flatnonzero(np.diff(self.report) != 0)
        return np.append(last, self.nsteps - 1).astype(np.int64)

    def report_steps(self) -> tuple[np.ndarray, np.ndarray]:
        """``(reports, dates)``: each report step's number and date (``datetime64[s]``)."""
        rows = self.report_index()
        return self.report[rows], self.dates[rows]

    # --- conversions ---------------------------------------------------------------------------
    def to_pandas(self):
        """A ``pandas.DataFrame`` (the ``parquet`` extra): indexed by date and time (``time``),
        a ``days`` column, then one column per vector named as ECLIPSE names it; ``attrs``:
        ``units`` ({column: unit}), ``kinds``, ``start``, ``unit_system``, ``report`` (the
        report step of each row, a list).

        >>> import numpy as np, datetime
        >>> t = SummaryTable([1.0], np.ones((1, 1), np.float32),
        ...                  [SummaryVector("FPR", "FPR", "field", "PSIA")],
        ...                  datetime.datetime(2000, 1, 1))
        >>> df = t.to_pandas()
        >>> list(df.columns), df.attrs["units"]["FPR"], str(df.index[0])
        (['days', 'FPR'], 'PSIA', '2000-01-02 00:00:00')
        """
        pd = require("pandas", "parquet", "SummaryTable.to_pandas")
        data = {"days": self.days}
        data.update({v.key: self.values[:, i] for i, v in enumerate(self.vectors)})
        df = pd.DataFrame(data, index=pd.DatetimeIndex(self.dates, name="time"))
        df.attrs.update(units={"days": "DAYS", **self.units()},
                        kinds={v.key: v.kind for v in self.vectors},
                        start=self.start.isoformat(), unit_system=self.unit_system,
                        report=self.report.tolist(), source=self.name)
        return df

    def to_xarray(self):
        """An ``xarray.Dataset`` (the ``netcdf`` extra): dimension ``time`` (dates), coordinates
        ``days`` and ``report``, one variable per vector with ``attrs["units"]`` and ``kind``.

        >>> import numpy as np, datetime
        >>> t = SummaryTable([1.0, 2.0], np.ones((2, 1), np.float32),
        ...                  [SummaryVector("WBHP:P", "WBHP", "well", "BARSA", "P")],
        ...                  datetime.datetime(2000, 1, 1))
        >>> ds = t.to_xarray()
        >>> ds["WBHP:P"].attrs["units"], ds.sizes["time"]
        ('BARSA', 2)
        """
        xr = require("xarray", "netcdf", "SummaryTable.to_xarray")
        coords = {"time": ("time", self.dates.astype("datetime64[ns]")),
                  "days": ("time", self.days, {"units": "DAYS"}),
                  "report": ("time", self.report)}
        data = {v.key: ("time", self.values[:, i], {"units": v.unit, "kind": v.kind})
                for i, v in enumerate(self.vectors)}
        return xr.Dataset(data, coords=coords,
                          attrs={"start": self.start.isoformat(),
                                 "unit_system": self.unit_system, "source": self.name})

    def __repr__(self) -> str:
        rows = [("Vectors", f"{len(self.vectors)}: {reprs.names(self.keys)}"),
                ("Ministeps", f"{reprs.count(self.nsteps)} in "
                              f"{len(self.report_index())} report steps"),
                ("Time", f"{self.iso_dates()[0]} – {self.iso_dates()[-1]}" if self.nsteps
                 else f"start {self.start.isoformat()}"),
                ("Units", self.unit_system)]
        return reprs.block("SummaryTable", self.name, rows)


def _int_array(a, default: np.ndarray, n: int, what: str, w: str) -> np.ndarray:
    out = default if a is None else np.asarray(a)
    if out.shape != (n,) or (out.size and out.dtype.kind not in "iu"):
        raise InputError(f"{w}{what}: expected shape ({n},) integers, got "
                         f"{out.shape} {out.dtype}")
    return out.astype(np.int32)


__all__ = ["KINDS", "UNIT_SYSTEMS", "SummaryTable", "SummaryVector", "match_vectors"]
