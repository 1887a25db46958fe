"""The real OPM Flow run of Reek (restart and summary files) and its oracles for the viewers'
summary plot and picks: resfo's reading of a cell, the pixel of a date on the plot."""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SHARED_DATA

#: EGRID, INIT, UNRST, SMSPEC and UNSMRY of 37 monthly report steps (shared/data/README.md)
REEK = SHARED_DATA / "reek_cornerpoint" / "opm_flow_run" / "2_R001_REEK-0.EGRID"

needs_reek = pytest.mark.skipif(
    not (REEK.is_file() and REEK.with_suffix(".UNSMRY").is_file()),
    reason=f"{REEK} and its summary are absent (shared data set, see shared/data/README.md)")


def resfo_cell(ijk, step: int, dims, active, path: Path = REEK) -> dict[str, float]:
    """Every INIT array's and report ``step``'s UNRST arrays' value of cell ``ijk`` (0-based),
    as resfo reads them: ``{NAME: value}`` (arrays of the active cells or of every cell)."""
    import resfo

    act = np.asarray(active, bool)
    n = int(np.ravel_multi_index(tuple(int(v) for v in ijk), tuple(dims), order="F"))
    index = int(np.count_nonzero(act.ravel(order="F")[:n]))
    nact, ncell = int(act.sum()), int(act.size)

    def value(arr):
        a = np.asarray(arr)
        if a.ndim != 1 or a.dtype.kind not in "fiu":
            return None
        return float(a[index]) if a.size == nact else float(a[n]) if a.size == ncell else None

    out = {}
    for key, arr in resfo.read(path.with_suffix(".INIT")):
        v = value(arr)
        if v is not None:
            out[key.strip()] = v
    seq = -1
    for key, arr in resfo.read(path.with_suffix(".UNRST")):
        if key.strip() == "SEQNUM":
            seq += 1
        elif seq == step:
            v = value(arr)
            if v is not None and key.strip() not in ("INTEHEAD", "LOGIHEAD", "DOUBHEAD"):
                out[key.strip()] = v
    return out


def x_of(layout: dict, date: str) -> float:
    """The pixel column of ``date`` on the summary plot whose layout is ``layout``."""
    x0, _, x1, _ = layout["axes"][0]["bbox"]
    lo, hi = (datetime.fromisoformat(d) for d in layout["xlim"])
    t = datetime.fromisoformat(date)
    return x0 + (t - lo) / (hi - lo) * (x1 - x0)


def y_mid(layout: dict) -> float:
    _, y0, _, y1 = layout["axes"][0]["bbox"]
    return (y0 + y1) / 2


def day(date: str) -> str:
    """The day of an ISO date or date-time."""
    return str(date)[:10]
