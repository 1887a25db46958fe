"""The memory plan before loading (issue 34, item 1).

- in process: every header equals what its reader reads (shape, dtype, active cells, a store's
  levels and coarse level, a stack model's intervals); the block reader equals numpy; a plan
  takes the first route that fits and refuses in one line with the figures;
- capped child processes (``RLIMIT_AS`` through :mod:`tests.hostile`, or a ``--memory``
  budget): a grid bigger than the cap is refused in one line naming the figures and the route
  (``geoshade grid ingest``); a grid store draws its coarse level; a raw volume whose mapping
  does not fit is drawn in bricks read by blocks (every selected voxel counted, against numpy);
  a stack model is drawn or refused; ``info`` shows the plan;
- one calibration test: the plan's figure of the route taken is within :data:`TOLERANCE` of the
  peak resident memory measured (``VmHWM``) for a grid, a core and a stack model.

No timing is asserted.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
import pytest

from tests.hostile import RESULTS, changed, one_error_line, record, run, snapshot, summary

PLAN = "5 memory plan"
#: the plan's estimate of the route taken against the measured peak RSS (the calibration
#: tables of grid/plan.py, core/plan.py and stacks/plan.py: within 10 %, two runs at 21 %)
TOLERANCE = 0.30
GIB = 1 << 30


def _egrid(folder, dims=(30, 20, 10), name="G"):
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.egrid_writer import write_egrid, write_init

    g = synthetic_grid(*dims, steps=0)
    write_egrid(g, folder / f"{name}.EGRID")
    write_init(g, folder / f"{name}.INIT")
    return folder / f"{name}.EGRID", g


def _huge_grdecl(folder, dims=(400, 400, 100)):
    """A legal GRDECL of ``dims`` cells in a few hundred bytes (repeat counts)."""
    nx, ny, nz = dims
    pillars = (nx + 1) * (ny + 1)
    text = (f"SPECGRID\n {nx} {ny} {nz} 1 F /\nCOORD\n {pillars * 6}*0 /\n"
            f"ZCORN\n {8 * nx * ny * nz}*1000 /\nACTNUM\n {nx * ny * nz}*1 /\n")
    (folder / "BIG.grdecl").write_text(text)
    return folder / "BIG.grdecl"


# --------------------------------------------------------------------------------------------
# in process: headers, blocks, the choice
# --------------------------------------------------------------------------------------------
def test_headers_equal_what_the_readers_read(tmp_path):
    import tifffile

    import geoshade
    from geoshade.compute.stacks import synthetic_layers
    from geoshade.io.layers.stackfile import write_stacks
    from geoshade.io.plan import read_header
    from geoshade.io.stores.zarr_io import write_zarr
    from geoshade.models import VoxelVolume

    a = np.random.default_rng(0).integers(0, 60000, (7, 9, 11)).astype("<u2")
    a.tofile(tmp_path / "v.raw")
    np.save(tmp_path / "v.npy", a)
    np.savez(tmp_path / "v.npz", data=a)
    tifffile.imwrite(tmp_path / "v.tif", a)
    write_zarr(VoxelVolume(a), tmp_path / "v.zarr")
    for name, hints, storage in [("v.raw", {"shape": (11, 9, 7), "dtype": "uint16"}, "mapped"),
                                 ("v.npy", {}, "mapped"), ("v.npz", {}, "held"),
                                 ("v.tif", {}, "mapped"), ("v.zarr", {}, "lazy")]:
        h = read_header(tmp_path / name, **hints)
        vol = geoshade.load(tmp_path / name, **hints)
        assert (h.shape, h.dtype, h.storage) == (vol.shape_xyz, vol.dtype.name, storage), name

    egrid, g = _egrid(tmp_path)
    for f in (egrid, tmp_path / "G.INIT"):
        h = read_header(f)
        assert (h.kind, h.shape, h.nactive) == ("grid", g.dims, g.nactive)
        assert h.arrays == len(geoshade.load(f).properties)
    from geoshade.io.grids.grdecl_writer import write_grdecl

    write_grdecl(g, tmp_path / "G.grdecl")
    assert read_header(tmp_path / "G.grdecl").shape == geoshade.load(tmp_path / "G.grdecl").dims
    assert read_header(_huge_grdecl(tmp_path)).shape == (400, 400, 100)

    m = synthetic_layers(40, 30, 20, seed=2)
    write_stacks(tmp_path / "m.stacks.npz", m)
    h = read_header(tmp_path / "m.stacks.npz")
    assert (h.kind, h.shape, h.intervals) == ("stacks", m.shape, m.nintervals)
    record(PLAN, "headers equal the readers (raw, npy, npz, tiff, zarr, EGRID, INIT, GRDECL, "
                 "stacks)", "")


def test_grid_store_header(tmp_path):
    from geoshade.compute.grid.faces import visible_faces
    from geoshade.compute.grid.index_faces import store_index
    from geoshade.grid.lod import write_coarse_level
    from geoshade.io.plan import read_header
    from geoshade.io.stores.grid_lod import read_coarse_level
    from geoshade.io.stores.grid_store import ingest_grid

    egrid, g = _egrid(tmp_path, (24, 20, 8))
    ingest_grid(egrid, tmp_path / "G.zarr", chunks=(16, 16, 4), index=store_index)
    write_coarse_level(tmp_path / "G.zarr", 2)
    h = read_header(tmp_path / "G.zarr")
    level = read_coarse_level(tmp_path / "G.zarr")
    assert (h.kind, h.shape, h.nactive) == ("grid-store", g.dims, g.nactive)
    assert h.faces == len(visible_faces(g).face)
    assert h.coarse["factor"] == 2 and tuple(h.coarse["dims"]) == level.dims
    record(PLAN, "grid store header (dims, active cells, index faces, coarse level)", "")


def test_file_blocks_equal_numpy(tmp_path):
    from geoshade.io import load
    from geoshade.io.volumes.slabs import FileBlocks, unmapped

    rng = np.random.default_rng(3)
    a = rng.integers(0, 2**16, (37, 29, 41)).astype(">u2")
    a.tofile(tmp_path / "b.raw")
    blocks = FileBlocks(tmp_path / "b.raw", ">u2", 0, a.shape)
    for _ in range(50):
        key = tuple(slice(int(lo), int(lo) + int(n), int(st)) for lo, n, st in
                    zip(rng.integers(0, 20, 3), rng.integers(1, 25, 3), rng.integers(1, 4, 3),
                        strict=True))
        assert np.array_equal(blocks[key], a[key]), key
    assert blocks[5, 3, 7] == a[5, 3, 7]
    vol = load(tmp_path / "b.raw", shape=(41, 29, 37), dtype="uint16", endian="big")
    u = unmapped(vol)
    assert not isinstance(u.data, np.memmap)
    assert np.array_equal(np.asarray(u.data.compute()), np.asarray(vol.data))
    record(PLAN, "blocks read without a map equal numpy", "")


def test_the_first_route_that_fits_is_taken():
    from geoshade.io.plan import Header, Machine, Plan, Route

    h = Header("g.EGRID", "eclipse", "grid", (100, 100, 10))
    routes = [Route("memory", "in memory", 3 * GIB, 4 * GIB, None),
              Route("store", "from the store", GIB, 2 * GIB, None),
              Route("coarse", "from the store's coarse level", GIB // 4, GIB, None,
                    reduced="coarse level")]
    p = Plan(h, Machine(8 * GIB, "MemAvailable"), routes)
    assert p.chosen.name == "memory"
    p = Plan(h, Machine(2 * GIB, "--memory"), routes)
    assert p.chosen.name == "store" and "drawing from the store" in p.line()
    p = Plan(h, Machine(2 * GIB, "--memory", address_space=int(1.5 * GIB)), routes)
    assert p.chosen.name == "coarse" and "coarse level" in p.stats()["reduced"]
    p = Plan(h, Machine(GIB // 8, "--memory"), routes)
    line = p.refusal()
    assert p.chosen is None and "\n" not in line
    for needle in ("3.0 GiB", "128 MiB --memory", "1.0 GiB from the store", "256 MiB"):
        assert needle in line, (needle, line)
    record(PLAN, "the first route that fits; one refusal line with the figures", "")


def test_a_fifo_named_zarr_json_is_never_opened(tmp_path):
    from geoshade.io.stores.headers import zarr_header

    d = tmp_path / "f.zarr"
    d.mkdir()
    os.mkfifo(d / "zarr.json")
    assert zarr_header(d) is None   # returned at once: a blocking open would hang here
    record(PLAN, "a FIFO named zarr.json: no plan, no hang", "")


# --------------------------------------------------------------------------------------------
# capped child processes
# --------------------------------------------------------------------------------------------
def test_grid_bigger_than_the_cap_is_refused_in_one_line(tmp_path):
    """A 16-million-cell GRDECL (a few hundred bytes) under ``ulimit -v 1.5 GiB``: one line
    with the figures and ``geoshade grid ingest``, before any value is parsed."""
    _huge_grdecl(tmp_path)
    before = snapshot(tmp_path)
    r = run(["geoshade", "grid", "render", "BIG.grdecl", "-o", "big.png", "--size", "64x48"],
            tmp_path, rlimit_as=int(1.5 * GIB), timeout=300)
    why = one_error_line(r, "BIG.grdecl", "in memory needs", "GiB", "RLIMIT_AS",
                         "geoshade grid ingest BIG.grdecl -o") or (
        "" if r.rc == 6 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    why = why or ("" if r.maxrss_mb < 500 else f"peak {r.maxrss_mb:.0f} MB")
    record(PLAN, "grid 1.6e7 cells under ulimit -v 1.5 GiB: refused", why, r)


@pytest.mark.gl
def test_grid_store_draws_its_coarse_level_within_the_budget(tmp_path):
    """A budget between the store's figure and its coarse level's: the coarse level is drawn
    (its cells, the route and what was reduced in the stats; the title says it), under an
    address-space cap as well."""
    from geoshade.api import plan
    from geoshade.io.stores.grid_lod import read_coarse_level

    egrid, _ = _egrid(tmp_path, (60, 50, 20))
    r = run(["geoshade", "grid", "ingest", egrid.name, "-o", "G.zarr", "--coarse", "2"],
            tmp_path, timeout=600)
    assert r.rc == 0, r.err
    p = plan(tmp_path / "G.zarr")
    full, coarse = p.route("store"), p.route("coarse")
    budget = int((full.ram + coarse.ram) / 2 * 1.1)
    cap = int(coarse.vm * 1.1) + (400 << 20)
    r = run(["geoshade", "grid", "render", "G.zarr", "-o", "c.png", "--size", "96x72",
             "--memory", str(budget), "--stats", "c.json", "--frames", "1"], tmp_path,
            rlimit_as=cap, timeout=600)
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]}"
    if not why:
        st = json.loads((tmp_path / "c.json").read_text())
        level = read_coarse_level(tmp_path / "G.zarr")
        why = "" if st["plan"]["route"] == "coarse" else f"route {st['plan']['route']}"
        why = why or ("" if st["active_cells"] == level.nactive else
                      f"{st['active_cells']} cells drawn, the level has {level.nactive}")
        why = why or ("" if "cells merged 2×2×2" in st["plan"]["reduced"] else
                      st["plan"]["reduced"])
        why = why or ("" if any("coarse level" in ln and "geoshade: plan:" in ln
                                for ln in r.lines) else f"no plan line: {r.lines}")
    record(PLAN, "grid store, budget below the store: its coarse level drawn", why, r)


def _raw(folder, n=512):
    a = np.random.default_rng(5).integers(0, 256, (n, n, n), dtype=np.uint8)
    a.tofile(folder / "c.raw")
    return a


@pytest.mark.gl
def test_raw_volume_beyond_its_mapping_is_drawn_in_bricks(tmp_path):
    """A 512³ raw volume under an address-space cap that its mapped drawing exceeds but its
    bricks read by blocks fit: a picture, route ``bricks`` in the stats, every selected voxel
    counted (numpy's count); below the bricks, one line with the figures and the routes."""
    from geoshade.api import plan
    from geoshade.io.plan import Machine

    a = _raw(tmp_path)
    hints = {"shape": (512, 512, 512), "dtype": "uint8"}
    cap = None   # the smallest limit (by 32 MiB) under which the plan draws bricks
    for mib in range(1024, 4096, 32):
        p = plan(tmp_path / "c.raw", machine=Machine(64 * GIB, "test", mib << 20), **hints)
        if p.chosen is not None and p.chosen.name == "bricks":
            cap = (mib + 32) << 20
            break
    p = plan(tmp_path / "c.raw", machine=Machine(64 * GIB, "test", cap), **hints)
    if cap is None or p.chosen.name != "bricks":
        pytest.skip("no address-space limit under which the plan draws bricks")
    argv = ["geoshade", "core", "render", "c.raw", "--shape", "512", "512", "512", "--dtype",
            "uint8", "--select", "10", "60", "--sample", "none", "--size", "96x72",
            "--frames", "1"]
    r = run([*argv, "-o", "b.png", "--stats", "b.json"], tmp_path, rlimit_as=cap, timeout=900)
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]}"
    if not why:
        st = json.loads((tmp_path / "b.json").read_text())
        want = int(np.count_nonzero((a >= 10) & (a <= 60)))
        why = "" if st["plan"]["route"] == "bricks" else f"route {st['plan']['route']}"
        why = why or ("" if st["voxels_selected"] == want else
                      f"{st['voxels_selected']} voxels selected, numpy counts {want}")
        why = why or ("" if st.get("brick_mode") in ("streamed", "resident") else "not bricked")
    record(PLAN, f"raw 512³ under ulimit -v {cap >> 20} MiB: drawn in bricks", why, r)

    before = snapshot(tmp_path)
    r = run([*argv, "-o", "n.png"], tmp_path, rlimit_as=int(1.2 * GIB), timeout=300)
    why = one_error_line(r, "c.raw", "in memory needs", "whole volume", "in bricks",
                         "geoshade core ingest", "RLIMIT_AS") or (
        "" if r.rc == 6 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(PLAN, "raw 512³ under ulimit -v 1.2 GiB: refused", why, r)


@pytest.mark.gl
def test_stack_model_drawn_or_refused(tmp_path):
    """A stack model: drawn under a cap its figure fits (route in the stats, every interval
    there), refused in one line under one it does not."""
    from geoshade.api import plan
    from geoshade.compute.stacks import synthetic_layers
    from geoshade.io.layers.stackfile import write_stacks

    m = synthetic_layers(512, 512, 40, max_intervals=6, seed=3)
    write_stacks(tmp_path / "m.stacks.npz", m)
    p = plan(tmp_path / "m.stacks.npz")
    cap = int(p.first.vm * 1.1) + (200 << 20)
    r = run(["geoshade", "stacks", "render", "m.stacks.npz", "-o", "m.png", "--size", "96x72",
             "--stats", "m.json", "--frames", "1"], tmp_path, rlimit_as=cap, timeout=600)
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]}"
    if not why:
        st = json.loads((tmp_path / "m.json").read_text())
        why = "" if st["plan"]["route"] == "memory" else f"route {st['plan']['route']}"
        why = why or ("" if st["intervals"] == m.nintervals else
                      f"{st['intervals']} intervals, the model has {m.nintervals}")
    record(PLAN, f"stack model under ulimit -v {cap >> 20} MiB: drawn", why, r)

    before = snapshot(tmp_path)
    r = run(["geoshade", "stacks", "render", "m.stacks.npz", "-o", "n.png", "--size", "96x72",
             "--memory", "150M"], tmp_path, rlimit_as=int(0.9 * GIB), timeout=300)
    why = one_error_line(r, "m.stacks.npz", "in memory needs", "MiB", "in memory only") or (
        "" if r.rc == 6 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(PLAN, "stack model under ulimit -v 0.9 GiB and --memory 150M: refused", why, r)


def test_info_shows_the_plan(tmp_path):
    """``info`` says every route with its figures and whether it fits; a grid whose reading
    does not fit is not read (its plan is shown)."""
    _huge_grdecl(tmp_path)
    r = run(["geoshade", "info", "BIG.grdecl", "--memory", "1G"], tmp_path, timeout=300)
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]}"
    for needle in ("(not read)", "plan     400×400×100 cells", "in memory", "NO",
                   "from a store", "geoshade grid ingest BIG.grdecl"):
        why = why or ("" if needle in r.out else f"{needle!r} not in {r.out[-400:]!r}")
    why = why or ("" if r.maxrss_mb < 500 else f"peak {r.maxrss_mb:.0f} MB")
    record(PLAN, "info of a grid beyond the budget: the plan, not read", why, r)

    _egrid(tmp_path)
    r = run(["geoshade", "info", "G.EGRID", "--json"], tmp_path, timeout=300)
    d = json.loads(r.out) if r.rc == 0 else {}
    routes = {x["name"]: x for x in d.get("plan", {}).get("routes", [])}
    why = "" if r.rc == 0 else f"exit {r.rc}"
    why = why or ("" if {"memory", "store", "cluster"} <= set(routes) else f"routes {routes}")
    why = why or ("" if routes["memory"]["fits"] and d["plan"]["chosen"] == "memory" else
                  json.dumps(d["plan"])[:300])
    record(PLAN, "info --json of a small grid: the plan, in memory", why, r)


# --------------------------------------------------------------------------------------------
# calibration
# --------------------------------------------------------------------------------------------
@pytest.mark.gl
@pytest.mark.parametrize("case", ["grid", "core", "stacks"])
def test_plan_figures_within_tolerance_of_measured_peaks(tmp_path, case):
    """The figure of the route taken against the child's measured peak RSS (``VmHWM``)."""
    from geoshade.api import plan

    if case == "grid":
        _egrid(tmp_path, (200, 100, 25))
        argv, path, hints = ["grid", "render", "G.EGRID"], "G.EGRID", {}
    elif case == "core":
        _raw(tmp_path, 256)
        hints = {"shape": (256, 256, 256), "dtype": "uint8"}
        argv = ["core", "render", "c.raw", "--shape", "256", "256", "256", "--dtype", "uint8",
                "--select", "0", "100"]
        path = "c.raw"
    else:
        from geoshade.compute.stacks import synthetic_layers
        from geoshade.io.layers.stackfile import write_stacks

        write_stacks(tmp_path / "m.stacks.npz",
                     synthetic_layers(1024, 512, 40, max_intervals=6, seed=3))
        argv, path, hints = ["stacks", "render", "m.stacks.npz"], "m.stacks.npz", {}
    want = plan(tmp_path / path, **hints).chosen.ram / 2**20
    r = run(["geoshade", *argv, "-o", "o.png", "--size", "320x240"], tmp_path, timeout=600)
    got = r.maxrss_mb
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]}"
    why = why or ("" if abs(want - got) <= TOLERANCE * got else
                  f"estimate {want:.0f} MiB, measured {got:.0f} MiB")
    record(PLAN, f"{case}: estimate {want:.0f} MiB, measured {got:.0f} MiB", why, r)


def test_zz_counts():
    """The tried / clean table of this file (``pytest -s`` prints it)."""
    if PLAN in RESULTS:
        print(summary(PLAN))
        assert all(ok for _, ok, _ in RESULTS[PLAN]), summary(PLAN)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-s"]))
