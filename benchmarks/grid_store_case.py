"""The generated faulted case of ``grid_cases.py``, written chunk by chunk straight into a grid
store (no EGRID in between): the (2000, 2000, 250) case of issue 16 needs 32 GB of ZCORN alone,
so it never exists as files or in memory.

:class:`CaseSource` gives :func:`geoshade.io.stores.grid_store.write_grid_store` the case's slabs
(the
protocol of :class:`geoshade.io.stores.grid_store.GridSource`), layer by layer from
:class:`grid_cases.Case`; inactive cells hold NaN in PORO/PERMX/SWAT, as an ingested EGRID's do.
The writer stores each array's colour-scale summary as it goes (the view needs no pass over a
property to colour it).

Run ``python benchmarks/grid_store_case.py OUT.zarr NX NY NZ [--steps N] [--chunks CI CJ CK]``.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from grid_cases import Case


class CaseSource:
    """A :class:`grid_cases.Case` as a grid-store source (slabs of layers, computed on demand)."""

    def __init__(self, nx: int, ny: int, nz: int, steps: int = 2):
        self.case = Case(nx, ny, nz, steps)
        self.dims = (nx, ny, nz)
        self.name = f"generated {nx}x{ny}x{nz}"
        self.units, self.mapaxes, self.faults = "METRES", None, []
        self.properties = {"PORO": np.float32, "PERMX": np.float32}
        self.step_keywords = {"SWAT": np.float32} if steps else {}
        self.step_dates = [f"{2000 + t // 12:04d}-{1 + t % 12:02d}-01" for t in range(steps)]
        self.step_seqnum = list(range(steps))
        self.fingerprint = hashlib.sha1(f"grid_cases.Case|{nx}|{ny}|{nz}|{steps}".encode()
                                        ).hexdigest()
        self.meta = {"format": "generated", "mapunits": "METRES"}

    def coord(self) -> np.ndarray:
        return self.case.coord().transpose(1, 0, 2).astype(np.float64)

    def zcorn(self, k0: int, k1: int) -> np.ndarray:
        nx, ny, _ = self.dims
        out = np.empty((2 * nx, 2 * ny, 2 * (k1 - k0)), np.float32, order="F")
        for k in range(k0, k1):
            out[:, :, 2 * (k - k0):2 * (k - k0) + 2] = self.case.zcorn_layer(k)
        return out

    def actnum(self, k0: int, k1: int) -> np.ndarray:
        return np.stack([self.case.actnum_layer(k) for k in range(k0, k1)], 2).astype(np.uint8)

    def _cells(self, fn, k0, k1, act) -> np.ndarray:
        v = np.stack([fn(k) for k in range(k0, k1)], 2).astype(np.float32)
        v[act == 0] = np.nan
        return v

    def prop(self, name, k0, k1, act, a0) -> np.ndarray:
        fn = {"PORO": self.case.poro_layer, "PERMX": self.case.permx_layer}[name]
        return self._cells(fn, k0, k1, act)

    def step(self, t, kw, k0, k1, act, a0) -> np.ndarray:
        return self._cells(lambda k: self.case.swat_layer(k, t), k0, k1, act)


def write_store_case(out, nx: int, ny: int, nz: int, steps: int = 2, chunks=(128, 128, 16),
                     progress=None, overwrite: bool = False, index: bool = True,
                     coarse=None, compressor: str = "zstd"):
    """Write the generated case into a grid store at ``out`` with its index (as
    ``geoshade grid ingest`` writes one) and, with ``coarse`` (2, 4, 8, "auto"), a coarse level
    of detail; ``compressor``: the chunks' blosc codec (``lz4`` for a store meant for
    interaction: see ``benchmarks/RESULTS.md``, billion section); the ingest report."""
    from geoshade.compute.grid.index_faces import store_index
    from geoshade.grid.lod import write_coarse_level
    from geoshade.io.stores.grid_store import write_grid_store

    rep = write_grid_store(CaseSource(nx, ny, nz, steps), out, chunks, progress=progress,
                           overwrite=overwrite, input_label=f"generated:{nx}x{ny}x{nz}",
                           compressor=compressor,
                           index=store_index if index else None)
    if coarse is not None:
        write_coarse_level(rep.path, coarse)
    return rep


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("dims", nargs=3, type=int)
    ap.add_argument("--steps", type=int, default=2)
    ap.add_argument("--chunks", nargs=3, type=int, default=(128, 128, 16))
    ap.add_argument("--overwrite", action="store_true")
    ap.add_argument("--no-index", action="store_true",
                    help="write the store without its index (an old store)")
    ap.add_argument("--coarse", default=None,
                    help="also keep a coarse level of detail (2, 4, 8 or auto)")
    ap.add_argument("--compressor", default="zstd", choices=("zstd", "lz4", "lz4hc", "zlib"),
                    help="blosc codec of the chunks (as geoshade grid ingest --compressor)")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()

    def say(done, total):
        print(f"slab {done}/{total} ({time.perf_counter() - t0:.0f} s)", file=sys.stderr,
              flush=True)

    rep = write_store_case(a.out, *a.dims, steps=a.steps, chunks=a.chunks, progress=say,
                           overwrite=a.overwrite, index=not a.no_index,
                           compressor=a.compressor,
                           coarse=None if a.coarse is None else
                           (a.coarse if a.coarse == "auto" else int(a.coarse)))
    print(f"{rep.path}: {rep.slabs} slabs in {rep.seconds:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
