"""What a grid store is written from: a source of k-slabs (:class:`GridSource`), read from an
ECLIPSE/OPM case piece by piece (:class:`geoshade.io.stores.ecl_source.EclSource`, the ``source``
of the ``eclipse`` row of :mod:`geoshade.io.formats`), from a GRDECL file or deck slab by slab
(:class:`geoshade.io.grids.grdecl_stream.GrdeclSource`) or taken from a grid in memory
(:class:`ModelSource`). :mod:`geoshade.io.stores.grid_store` writes them (see there)."""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import numpy as np

from geoshade.models import CornerPointGrid


def file_print(path) -> str:
    """A hash of a file's resolved path, size and modification time (changes when it does)."""
    p = Path(path)
    st = p.stat()
    return hashlib.sha1(f"{p.resolve()}|{st.st_size}|{st.st_mtime_ns}".encode()).hexdigest()


# --------------------------------------------------------------------------------------------
# sources: what the writer streams, slab by slab
# --------------------------------------------------------------------------------------------
class GridSource:
    """A corner-point grid the writer reads slab by slab (the protocol of every source).

    Attributes: ``dims``, ``name``, ``units``, ``mapaxes``, ``faults`` (list of Fault),
    ``properties`` (name -> dtype), ``step_keywords`` (name -> dtype), ``step_dates``,
    ``step_seqnum``, ``fingerprint`` (str: changes when the input does), ``meta`` (dict).
    Methods: ``coord()``, ``zcorn(k0, k1)``, ``actnum(k0, k1)``, ``prop(name, k0, k1, act,
    a0)``, ``step(t, kw, k0, k1, act, a0)`` where ``act`` is the slab's ACTNUM and ``a0`` the
    number of active cells before layer ``k0``.
    """

    dims: tuple[int, int, int]
    name: str
    units: str
    mapaxes: np.ndarray | None
    faults: list
    properties: dict
    step_keywords: dict
    step_dates: list
    step_seqnum: list
    fingerprint: str
    meta: dict


class ModelSource(GridSource):
    """An in-memory :class:`CornerPointGrid` (a GRDECL file, a synthetic grid) as a source."""

    def __init__(self, grid: CornerPointGrid, source: str = ""):
        self.grid = grid
        self.dims, self.name = grid.dims, source or grid.name
        self.units, self.mapaxes, self.faults = grid.units, grid.mapaxes, list(grid.faults)
        self.properties = {k: np.asarray(v).dtype for k, v in grid.properties.items()}
        first = grid.steps[0] if grid.steps else {}
        self.step_keywords = {k: np.asarray(first[k]).dtype for k in first
                              if all(k in s for s in grid.steps)}
        self.step_dates = list(grid.step_dates) or [""] * len(grid.steps)
        self.step_seqnum = list(grid.meta.get("unrst_seqnum", range(len(grid.steps))))
        self.fingerprint = hashlib.sha1(f"{id(grid)}|{time.time()}".encode()).hexdigest() \
            if not source else file_print(source)
        self.meta = {"format": str(grid.meta.get("format", "")),
                     "mapunits": str(grid.meta.get("mapunits", ""))}
        names = grid.meta.get("codes")   # a property's code names (ROFF): the legend's
        if isinstance(names, dict) and names:
            self.meta["codes"] = {str(n): {str(int(c)): str(t) for c, t in d.items()}
                                  for n, d in names.items() if isinstance(d, dict)}

    def coord(self):
        return np.asarray(self.grid.coord, np.float64)

    def zcorn(self, k0, k1):
        return np.asarray(self.grid.zcorn[:, :, 2 * k0:2 * k1], np.float32)

    def actnum(self, k0, k1):
        return (np.asarray(self.grid.actnum[:, :, k0:k1]) != 0).astype(np.uint8)

    def prop(self, name, k0, k1, act, a0):
        return np.asarray(self.grid.properties[name][:, :, k0:k1])

    def step(self, t, kw, k0, k1, act, a0):
        return np.asarray(self.grid.steps[t][kw][:, :, k0:k1])


__all__ = ["GridSource", "ModelSource", "file_print"]
