"""A grid store viewed on ``scheduler="local:N"``: the time of the open, of each filter change
and of ``release()``, and how many LocalClusters were started (issue 23: the View owns one
cluster for its life; before, one was started and stopped on every filter change).

Run ``python benchmarks/cluster_session.py [NX NY NZ] [--workers N]``; it prints one line per
step. Not a test: the figures depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile
import time
import warnings

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from grid_cases import write_case

FILTERS = ("PORO > 0.2", "PORO > 0.25", "PERMX > 100", None)


def main(argv=None) -> int:
    import distributed

    from geoshade.grid import GridView
    from geoshade.io.stores.grid_store import ingest_grid, open_grid_store

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("dims", nargs="*", type=int, default=[30, 21, 7])
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args(argv)
    warnings.simplefilter("ignore")
    started = [0]
    real = distributed.LocalCluster.__init__

    def counting(self, *a, **k):
        started[0] += 1
        real(self, *a, **k)

    distributed.LocalCluster.__init__ = counting
    folder = pathlib.Path(tempfile.mkdtemp())
    paths = write_case(folder, *args.dims, steps=2)
    ingest_grid(paths["EGRID"], folder / "c.zarr", chunks=(8, 8, 3))
    grid = open_grid_store(folder / "c.zarr")
    t0 = time.perf_counter()
    view = GridView(grid, size=(160, 120), annotations=False, property="PORO",
                    scheduler=f"local:{args.workers}")
    print(f"open: {time.perf_counter() - t0:.2f} s, LocalClusters started: {started[0]}")
    for f in FILTERS:
        t0 = time.perf_counter()
        view.update(filter=f)
        view.draw(frames=1)
        print(f"filter {f!r}: {time.perf_counter() - t0:.2f} s, LocalClusters started: "
              f"{started[0]}")
    t0 = time.perf_counter()
    view.release()
    print(f"release: {time.perf_counter() - t0:.2f} s, LocalClusters started: {started[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
