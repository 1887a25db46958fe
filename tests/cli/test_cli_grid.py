"""``geoshade grid render`` end to end: outputs, stats, one-line errors, and Reek."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import geoshade.cli.grid
import geoshade.io
from geoshade.cli.main import main
from tests.gl.grid_support import make_grid

STATS_KEYS = ("width", "height", "method", "frame_ms", "gpu_bytes", "cells", "active_cells",
              "faces_drawn", "approach", "zcorn_bits", "zcorn_max_error", "property", "step")


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture
def case(tmp_path, monkeypatch):
    """A faulted 8×5×4 grid with 2 report steps behind the path ``case.grdecl``."""
    grid = make_grid(8, 5, 4, throw=5.0, fault_i=4, inactive=[(1, 1, 1)], steps=2)
    path = tmp_path / "case.grdecl"
    path.write_text("-- stands for the grid returned by the patched loader\n")
    real_load = geoshade.io.load

    def load(p, **kw):
        return grid if str(p) == str(path) else real_load(p, **kw)

    monkeypatch.setattr(geoshade.io, "load", load)
    monkeypatch.setattr(geoshade.cli.grid, "load", load)   # imported at the command's top
    return path, grid


@pytest.mark.gl
@pytest.mark.parametrize("approach", ["2", "3"])
def test_render_writes_png_and_stats(capsys, tmp_path, case, approach):
    path, _ = case
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc, text, err = run(capsys, "grid", "render", path, "--property", "SWAT", "--step", 1,
                        "--approach", approach, "--edges", "--faults", "highlight",
                        "--filter", "PORO > 0.1", "--slice", "i=1:8,k=0:3", "--size", "64x48",
                        "--frames", 1, "-o", out, "--stats", stats)
    assert rc == 0, err
    assert np.asarray(Image.open(out)).shape == (48, 64, 4)
    s = json.loads(stats.read_text())
    for key in STATS_KEYS:
        assert key in s, key
    assert (s["width"], s["height"], s["property"], s["step"]) == (64, 48, "SWAT", 1)
    assert s["cells"] == 160 and s["active_cells"] == 159
    assert s["faces_drawn"] == s["faces"] > 0
    assert s["approach"] == int(approach)
    assert str(out) in text


@pytest.mark.gl
def test_clip_exaggeration_and_approach1_smear(capsys, tmp_path, case):
    path, _ = case
    out = tmp_path / "c.png"
    rc, _, err = run(capsys, "grid", "render", path, "--approach", 1, "--smear-faults",
                     "--clip", "1,0,0,-10", "--exaggeration", 2, "--view", "top", "--ortho",
                     "--transparent", "--size", "48x48", "--frames", 1, "-o", out)
    assert rc == 0, err
    alpha = np.asarray(Image.open(out))[..., 3]
    assert 0 < (alpha > 0).mean() < 1


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (("--property", "NOPE"), "unknown name 'NOPE'"),
        (("--property", "SWAT", "--step", 7), "step 7 does not exist; there are 2 steps"),
        (("--filter", "PORO > 0.1 and FOO < 3"), "FOO"),
        (("--slice", "i=5:2"), "slice"),
        (("--slice", "q=1:2"), "slice"),
        (("--slice", "i=0:99"), "slice"),
        (("--clip", "1,2"), "clip"),
        # approach 1 finds mismatched nodes while it packs the geometry for the GPU
        pytest.param(("--approach", 1, "--no-smear-faults"), "conforming", marks=pytest.mark.gl),
        (("--exaggeration", -1), "exaggeration"),
        (("--wells", "no_such_wells.txt"), "no_such_wells.txt"),
        (("--size", "64by48"), "size"),
    ],
)
def test_bad_input_one_line(capsys, tmp_path, case, args, expect):
    path, _ = case
    out = tmp_path / "bad.png"
    rc, _, err = run(capsys, "grid", "render", path, "--size", "32x32", *args, "-o", out)
    assert rc != 0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
    assert expect in lines[0], lines[0]
    assert "Traceback" not in err
    assert not out.exists()


def test_missing_case_names_file(capsys, tmp_path):
    rc, _, err = run(capsys, "grid", "render", tmp_path / "nope.grdecl", "-o", tmp_path / "x.png")
    assert rc != 0 and "nope.grdecl" in err and len(err.strip().splitlines()) == 1


# --- the real Reek grid -----------------------------------------------------------------------
@pytest.mark.gl
@pytest.mark.data
@pytest.mark.parametrize(("approach", "extra"), [(3, ()), (3, ("--zcorn-store", "grid")),
                                                 (2, ("--zcorn-bits", "32")),
                                                 (1, ("--smear-faults",))])
def test_reek_renders_with_each_approach(capsys, tmp_path, shared_data, approach, extra):
    case = shared_data / "reek_cornerpoint" / "include" / "grid" / "reek.grid"
    out, stats = tmp_path / "reek.png", tmp_path / "reek.json"
    rc, _, err = run(capsys, "grid", "render", case, "--approach", approach, *extra, "--edges",
                     "--size", "96x64", "--frames", 1, "--no-annotations", "-o", out,
                     "--stats", stats)
    assert rc == 0, err
    s = json.loads(stats.read_text())
    assert s["cells"] == 40 * 64 * 14 and s["faces_drawn"] == s["faces"] > 1000
    img = np.asarray(Image.open(out).convert("RGB"))
    assert (img != 255).any(-1).mean() > 0.1


@pytest.mark.data
@pytest.mark.gl
def test_reek_approach1_smears_or_is_refused(capsys, tmp_path, shared_data):
    case = shared_data / "reek_cornerpoint" / "include" / "grid" / "reek.grid"
    rc, _, err = run(capsys, "grid", "render", case, "--approach", 1, "--size", "32x32",
                     "--no-smear-faults", "-o", tmp_path / "x.png")
    assert rc != 0 and "conforming" in err and len(err.strip().splitlines()) == 1
    stats = tmp_path / "s.json"
    rc, _, err = run(capsys, "grid", "render", case, "--approach", 1, "--size", "32x32",
                     "-o", tmp_path / "y.png", "--stats", stats)
    assert rc == 0 and "smeared the faults" in err
    assert json.loads(stats.read_text())["smeared_nodes"] > 0


@pytest.mark.gl
def test_wells_file_is_drawn(capsys, tmp_path, case):
    path, _ = case
    wells = tmp_path / "wells.txt"
    wells.write_text("WELL A\n25 25 900\n25 25 1030\nMARKER 25 25 1000 top\n"
                     "WELL B\n60 10 950\n70 30 1010\n")
    outs = {}
    for extra in ((), ("--wells", wells)):
        out, stats = tmp_path / f"w{len(extra)}.png", tmp_path / f"w{len(extra)}.json"
        rc, _, err = run(capsys, "grid", "render", path, *extra, "--size", "64x48",
                         "--frames", 1, "--no-annotations", "-o", out, "--stats", stats)
        assert rc == 0, err
        outs[len(extra)] = (np.asarray(Image.open(out)), json.loads(stats.read_text()))
    assert outs[2][1]["wells"] == 2 and "wells" not in outs[0][1]
    assert (outs[2][0] != outs[0][0]).any(-1).mean() > 0.002
    bad = tmp_path / "bad_wells.txt"
    bad.write_text("1 2 3\n")
    rc, _, err = run(capsys, "grid", "render", path, "--wells", bad, "-o", tmp_path / "b.png")
    assert rc != 0 and "bad_wells.txt" in err and len(err.strip().splitlines()) == 1


@pytest.mark.gl
@pytest.mark.data
def test_reek_egrid_steps_filter_and_deck_wells(capsys, tmp_path, shared_data):
    run_dir = shared_data / "reek_cornerpoint" / "opm_flow_run"
    out, stats = tmp_path / "e.png", tmp_path / "e.json"
    rc, _, err = run(capsys, "grid", "render", run_dir / "2_R001_REEK-0.EGRID", "--property",
                     "SWAT", "--step", 36, "--filter", "SWAT > 0.3 and PORO > 0.1",
                     "--faults", "highlight", "--size", "64x48", "--frames", 1, "-o", out,
                     "--stats", stats)
    assert rc == 0, err
    s = json.loads(stats.read_text())
    assert (s["property"], s["step"], s["active_cells"]) == ("SWAT", 36, 35817)
    assert 0 < s["shown_cells"] < s["active_cells"] and s["faces_drawn"] == s["faces"]
    rc, _, err = run(capsys, "grid", "render", run_dir / "2_R001_REEK-0.EGRID", "--property",
                     "SWAT", "--step", 37, "-o", tmp_path / "x.png")
    assert rc != 0 and "step" in err and "37" in err and len(err.strip().splitlines()) == 1
    deck = shared_data / "reek_cornerpoint" / "model" / "2_R001_REEK-0.DATA"
    rc, _, err = run(capsys, "grid", "render", deck, "--property", "PORO", "--size", "64x48",
                     "--frames", 1, "-o", out, "--stats", stats)
    assert rc == 0, err
    s = json.loads(stats.read_text())
    assert s["wells"] > 0 and s["property"] == "PORO"


# --- the benchmark's worker (``geoshade bench grid`` itself is not a test) ---------------------
BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_grid.py"


@pytest.mark.gl
@pytest.mark.skipif(not BENCH.is_file(), reason="benchmarks/ not in this checkout")
@pytest.mark.timeout(120)
def test_bench_worker_prints_json_with_the_fields():
    cfg = {"kind": "geoshade", "label": "3 faces", "approach": 3, "store": "faces", "bits": 16,
           "dims": [12, 10, 4], "size": [64, 48], "frames": 2}
    proc = subprocess.run([sys.executable, str(BENCH), "--worker", json.dumps(cfg)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    res = json.loads([ln for ln in proc.stdout.splitlines() if ln.startswith("{")][-1])
    assert res["ok"], res.get("traceback") or res.get("error")
    for key in ("faces", "faces_drawn", "frame_ms", "first_frame_ms", "edges_frame_ms",
                "property_switch_ms", "step_switch_ms", "filter_ms", "gpu_bytes",
                "peak_rss_mib", "coverage"):
        assert key in res, key
    assert res["gpu_bytes"] == res["gpu_plan"] and res["faces"] == res["faces_drawn"] > 0
    assert (res["width"], res["height"]) == (64, 48) and res["coverage"] > 0.05


def test_importing_the_grid_part_does_not_import_moderngl():
    code = ("import sys, geoshade.grid, geoshade.grid.api, geoshade.cli.grid; "
            "sys.exit(1 if 'moderngl' in sys.modules else 0)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
