"""GRDECL parse speed and peak memory: geoshade's streaming reader against xtgeo and resdata.

Files: the Reek grid (``../shared/data/reek_cornerpoint/include/grid/reek.grid``, when present)
and a generated GRDECL of ``compute.grid.synthetic`` (faults, 5 % inactive cells, PORO/PERMX/
NTG/FIPNUM; written by ``io.grdecl_writer.write_grdecl`` with ``N*value`` runs): 250×200×200 =
1e7 cells by default, 100×100×100 with ``--quick``, 400×250×200 = 2e7 with ``--full``.  The
generated file is kept in ``$TMPDIR/geoshade-grid-bench/`` and reused.

Each reader runs in its own subprocess; ``parse_s`` is the wall time of the read call after the
imports (for geoshade the first call in the process, so it includes loading numba's cached
kernels; ``warm_s`` is a second call), ``peak_rss_mb`` the process's VmHWM and ``rss_growth_mb``
VmHWM minus the RSS after the imports.  The numba cache is filled by a warm-up run first, so
compilation is never measured.

``run(args) -> (markdown, results)`` is called by ``bench_grid.py``; alone:
``python benchmarks/grid_parse.py [--quick|--full] [--no-peers]`` prints the table and writes
``results/grid_parse.json``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REEK = HERE.parent.parent / "shared" / "data" / "reek_cornerpoint" / "include" / "grid"
DIMS = {"quick": (100, 100, 100), "default": (250, 200, 200), "full": (400, 250, 200)}
READERS = ("geoshade", "xtgeo", "resdata")
TIMEOUT_S = 1800


# --- worker (one reader, one file, in its own process) ---------------------------------------
def _status_mb(field: str) -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    return float("nan")  # pragma: no cover - not Linux


def worker(reader: str, path: str) -> dict:
    """Import ``reader``, parse ``path`` once (geoshade: twice), report times and memory."""
    import warnings

    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    if reader == "geoshade":
        from geoshade.io.grids.grdecl import read_grdecl

        def read():
            g = read_grdecl(path)
            return g.dims, g.nactive
    elif reader == "xtgeo":
        import xtgeo

        def read():
            g = xtgeo.grid_from_file(path, fformat="grdecl")
            return tuple(g.dimensions), int(g.nactive)
    elif reader == "resdata":
        from resdata.grid import Grid

        def read():
            g = Grid.load_from_grdecl(path)
            return (g.nx, g.ny, g.nz), int(g.get_num_active())
    else:
        raise ValueError(reader)
    import_s = time.perf_counter() - t0
    rss0 = _status_mb("VmRSS")
    t0 = time.perf_counter()
    dims, nactive = read()
    parse_s = time.perf_counter() - t0
    out = {"reader": reader, "import_s": import_s, "parse_s": parse_s, "dims": list(dims),
           "nactive": nactive, "rss_after_import_mb": rss0}
    out["peak_rss_mb"] = _status_mb("VmHWM")
    out["rss_growth_mb"] = out["peak_rss_mb"] - rss0
    if reader == "geoshade":
        t0 = time.perf_counter()
        read()
        out["warm_s"] = time.perf_counter() - t0
    return out


def _run_worker(reader: str, path: Path) -> dict:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", reader, str(path)]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return {"reader": reader, "error": f"timed out after {TIMEOUT_S} s"}
    if r.returncode != 0:
        tail = (r.stderr or r.stdout).strip().splitlines()[-1:] or ["?"]
        return {"reader": reader, "error": tail[0][:200]}
    return json.loads(r.stdout.strip().splitlines()[-1])


# --- files -----------------------------------------------------------------------------------
def generated_file(dims) -> tuple[Path, float | None]:
    """The synthetic GRDECL of ``dims`` (generated once into the temp folder): (path, write_s)."""
    folder = Path(tempfile.gettempdir()) / "geoshade-grid-bench"
    folder.mkdir(exist_ok=True)
    nx, ny, nz = dims
    path = folder / f"synthetic_{nx}x{ny}x{nz}.grdecl"
    if path.is_file():
        return path, None
    code = ("import sys, time; from geoshade.compute.grid.synthetic import synthetic_grid; "
            "from geoshade.io.grids.grdecl_writer import write_grdecl; "
            "g = synthetic_grid(%d, %d, %d, steps=0); t = time.perf_counter(); "
            "write_grdecl(g, sys.argv[1]); print(time.perf_counter() - t)"
            % (nx, ny, nz))
    r = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True,
                       timeout=TIMEOUT_S)
    if r.returncode != 0:
        raise RuntimeError(f"generating {path.name} failed: {r.stderr.strip()[-300:]}")
    return path, float(r.stdout.strip().splitlines()[-1])


def _warm_numba() -> None:
    """Compile the scanner into numba's on-disk cache so that no timed run compiles."""
    code = ("import numpy as np, geoshade.io.grids.grdecl as g; s = g._kernels()['scan']; "
            "b = np.frombuffer(b'1 2*3 /', np.uint8); "
            "[s(b, 0, b.size, True, np.zeros(8, t), 0, 8, np.zeros(2, np.int64), np.zeros(1)) "
            "for t in (np.float64, np.float32, np.uint8, np.int32)]")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=TIMEOUT_S)


# --- table -----------------------------------------------------------------------------------
def _fmt(v, nd=2):
    return "—" if v is None else f"{v:,.{nd}f}"


def run(args) -> tuple[str, dict]:
    """Measure every reader on Reek and the generated file: (Markdown section, results)."""
    mode = "quick" if getattr(args, "quick", False) else \
        "full" if getattr(args, "full", False) else "default"
    readers = ("geoshade",) if getattr(args, "no_peers", False) else READERS
    _warm_numba()
    files = []
    if (REEK / "reek.grid").is_file():
        files.append({"name": "Reek (40×64×14)", "path": REEK / "reek.grid", "write_s": None})
    dims = DIMS[mode]
    path, write_s = generated_file(dims)
    files.append({"name": "synthetic {}×{}×{}".format(*dims), "path": path, "write_s": write_s})
    rows = []
    for f in files:
        size_mb = f["path"].stat().st_size / 1e6
        for reader in readers:
            res = _run_worker(reader, f["path"])
            res.update(file=f["name"], size_mb=size_mb, path=str(f["path"]))
            rows.append(res)
            print(f"  grid parse: {f['name']} {reader}: "
                  f"{res.get('parse_s', res.get('error'))}", file=sys.stderr, flush=True)
    targets = []
    lines = ["| file | cells | MB | reader | parse s | warm s | peak RSS MB | RSS growth MB |"
             " active cells | xtgeo / this |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    for f in files:
        frows = [r for r in rows if r["file"] == f["name"]]
        ref = next((r for r in frows if r["reader"] == "xtgeo" and "parse_s" in r), None)
        ours = next((r for r in frows if r["reader"] == "geoshade" and "parse_s" in r), None)
        for r in frows:
            if "error" in r:
                lines.append(f"| {f['name']} | | {r['size_mb']:,.0f} | {r['reader']} | "
                             f"failed: {r['error']} | | | | | |")
                continue
            cells = r["dims"][0] * r["dims"][1] * r["dims"][2]
            ratio = f"{ref['parse_s'] / r['parse_s']:.1f}×" if ref else "—"
            lines.append(f"| {f['name']} | {cells:,} | {r['size_mb']:,.1f} | {r['reader']} | "
                         f"{_fmt(r['parse_s'])} | {_fmt(r.get('warm_s'))} | "
                         f"{_fmt(r['peak_rss_mb'], 0)} | {_fmt(r['rss_growth_mb'], 0)} | "
                         f"{r['nactive']:,} | {ratio} |")
        if ref and ours:
            speedup = ref["parse_s"] / ours["parse_s"]
            targets.append({"file": f["name"], "target": "parse >= 2x faster than xtgeo",
                            "speedup": speedup, "met": speedup >= 2.0,
                            "same_active_cells": ref["nactive"] == ours["nactive"]})
    md = ["### GRDECL parsing (`benchmarks/grid_parse.py`)", "",
          f"Mode `{mode}`; each reader in its own process, parse time after the imports "
          "(geoshade: first call, numba kernels loaded from the disk cache; *warm*: a second "
          "call); peak RSS = VmHWM of the process. Generated files written by "
          "`io.grdecl_writer.write_grdecl`"
          + "".join(f" ({f['name']}: {f['write_s']:.1f} s)" for f in files if f["write_s"])
          + ".", "", *lines, ""]
    for t in targets:
        md.append(f"- {t['file']}: {t['speedup']:.1f}× faster than xtgeo — target ≥ 2×: "
                  f"{'**met**' if t['met'] else '**not met**'}"
                  f"{'' if t['same_active_cells'] else ' (active cell counts differ!)'}")
    results = {"mode": mode, "files": [{k: str(v) if isinstance(v, Path) else v
                                        for k, v in f.items()} for f in files],
               "rows": rows, "targets": targets}
    return "\n".join(md) + "\n", results


def main(argv=None) -> int:
    import argparse

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--worker", nargs=2, metavar=("READER", "PATH"), help=argparse.SUPPRESS)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--full", action="store_true")
    p.add_argument("--no-peers", action="store_true")
    args = p.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(*args.worker)))
        return 0
    md, results = run(args)
    print(md)
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    tmp = out / ".grid_parse.json.tmp"
    tmp.write_text(json.dumps(results, indent=2, default=str) + "\n")
    os.replace(tmp, out / "grid_parse.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
