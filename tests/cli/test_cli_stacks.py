"""``geoshade stacks convert|render`` end to end, GeoTOP included, and the bad inputs."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from geoshade.cli.main import main
from geoshade.compute.stacks import stacks_to_voxels, synthetic_layers
from geoshade.io.layers.stackfile import read_stacks

RENDER_KEYS = ("width", "height", "method", "frame_ms", "gpu_bytes", "columns", "intervals",
               "max_intervals", "mrays_per_s")


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture
def labels(tmp_path):
    """A 12×10×16 layered label volume as .npy (z up), 0 = empty."""
    m = synthetic_layers(12, 10, 16, max_intervals=4, seed=2)
    a = stacks_to_voxels(m, np.int16, fill=0)
    p = tmp_path / "labels.npy"
    np.save(p, a)
    return p, a


def test_convert_npy_writes_a_model_and_stats(capsys, tmp_path, labels):
    path, a = labels
    out, stats = tmp_path / "m.stacks.npz", tmp_path / "c.json"
    rc, text, err = run(capsys, "stacks", "convert", path, "-o", out, "--empty", 0,
                        "--stats", stats)
    assert rc == 0, err
    m = read_stacks(out)
    assert np.array_equal(stacks_to_voxels(m, np.int16, fill=0), a)
    s = json.loads(stats.read_text())
    for key in (*RENDER_KEYS, "bytes_voxels", "bytes_octree", "bytes_stacks"):
        assert key in s, key
    assert s["bytes_voxels"] == a.size * 4 and s["columns"] == 120
    assert s["intervals"] == m.nintervals and s["bytes_octree"] > 0
    assert str(out) in text


@pytest.mark.gl
def test_render_model_and_input_with_the_tools(capsys, tmp_path, labels):
    path, _ = labels
    model = tmp_path / "m.stacks.npz"
    assert run(capsys, "stacks", "convert", path, "-o", model, "--empty", 0,
               "--no-octree")[0] == 0
    drape = tmp_path / "map.png"
    Image.new("RGB", (8, 8), (200, 30, 30)).save(drape)
    out, stats = tmp_path / "r.png", tmp_path / "r.json"
    rc, _, err = run(capsys, "stacks", "render", model, "-o", out, "--size", "80x60",
                        "--layout", "l-supertexels", "--hide", 1, "--opacity", "2=0.5",
                        "--plane=-1,0,0,-9", "--drape", drape, "--exaggeration", 2,
                        "--legend", "--frames", 2, "--stats", stats, "--view", "iso")
    assert rc == 0, err
    img = np.asarray(Image.open(out))
    assert img.shape == (60, 80, 4)
    # the old --section (cut away n·p > d) draws the same picture, with a warning
    rc, _, err = run(capsys, "stacks", "render", model, "-o", tmp_path / "old.png", "--size",
                     "80x60", "--layout", "l-supertexels", "--hide", 1, "--opacity", "2=0.5",
                     "--section", "1,0,0,9", "--drape", drape, "--exaggeration", 2,
                     "--legend", "--frames", 1, "--view", "iso")
    assert rc == 0 and "section is deprecated: use plane" in err
    assert np.array_equal(np.asarray(Image.open(tmp_path / "old.png")), img)
    s = json.loads(stats.read_text())
    for key in RENDER_KEYS:
        assert key in s, key
    assert (s["method"], s["width"], s["hidden"], s["drape"]) == ("l-supertexels", 80, [1], True)
    rc, _, err = run(capsys, "stacks", "render", path, "--empty", 0, "-o", out, "--size",
                     "48x40", "--boreholes", "--frames", 1, "--walk", "paper")
    assert rc == 0 and "no borehole column" in err          # a warning, not an error


@pytest.mark.data
@pytest.mark.gl
def test_geotop_convert_and_render(capsys, tmp_path, shared_data):
    nc = shared_data / "geotop_usp" / "geotop_usp.nc"
    model, stats = tmp_path / "strat.stacks.npz", tmp_path / "c.json"
    rc, text, err = run(capsys, "stacks", "convert", nc, "--variable", "strat", "-o", model,
                        "--stats", stats)
    assert rc == 0, err
    s = json.loads(stats.read_text())
    assert s["columns"] == 285 and s["borehole_columns"] > 0
    assert s["bytes_voxels"] == 19 * 15 * 313 * 4 and s["bytes_stacks"] < 0.05 * s["bytes_voxels"]
    assert "borehole logs placed" in text
    out = tmp_path / "g.png"
    rc, text, err = run(capsys, "stacks", "render", model, "-o", out, "--size", "64x48",
                        "--boreholes", "--exaggeration", 20, "--frames", 1)
    assert rc == 0, err
    img = np.asarray(Image.open(out))
    assert (img[..., :3] != 255).any(axis=-1).any()


@pytest.mark.parametrize("args, what", [
    (("--hide", 42), "hide: unknown material code 42"),
    (("--hide", "x"), "hide: expected integer material codes"),
    (("--opacity", "2:0.5"), "opacity: expected CODE=A"),
    (("--plane", "1,0,0,1000"), "plane: 1,0,0,1000 misses the model"),
    (("--plane", "1,0"), "plane: expected NX,NY,NZ"),
    (("--drape", "DRAPE"), "cannot read image"),
])
def test_bad_render_inputs_are_one_line_errors(capsys, tmp_path, labels, args, what):
    path, _ = labels
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not an image")
    args = tuple(junk if a == "DRAPE" else a for a in args)
    rc, _, err = run(capsys, "stacks", "render", path, "--empty", 0, "-o", tmp_path / "o.png",
                     "--size", "32x24", *args)
    assert rc == 2 and what in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


@pytest.mark.data
def test_netcdf_without_the_variable_is_one_line(capsys, tmp_path, shared_data):
    nc = shared_data / "geotop_usp" / "geotop_usp.nc"
    rc, _, err = run(capsys, "stacks", "convert", nc, "--variable", "porosity", "-o",
                     tmp_path / "m.stacks.npz")
    assert rc == 2 and "no variable 'porosity'" in err and len(err.strip().splitlines()) == 1


def test_convert_refuses_a_model_name_without_the_suffix(capsys, tmp_path, labels):
    rc, _, err = run(capsys, "stacks", "convert", labels[0], "-o", tmp_path / "m.npz")
    assert rc == 2 and ".stacks.npz" in err


def test_info_describes_a_model(capsys, tmp_path, labels):
    model = tmp_path / "m.stacks.npz"
    run(capsys, "stacks", "convert", labels[0], "-o", model, "--empty", 0, "--no-octree")
    rc, text, err = run(capsys, "info", model)
    assert rc == 0, err
    assert "stacks" in text and "columns" in text


# --- the benchmark's workers (smoke: tiny configs; the benchmark itself is not a test) ------
BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_stacks.py"


def _bench_worker(cfg: dict) -> dict:
    proc = subprocess.run([sys.executable, str(BENCH), "--worker", json.dumps(cfg)],
                          capture_output=True, text=True, timeout=120)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    assert proc.returncode == 0 and lines, proc.stderr[-2000:]
    res = json.loads(lines[-1])
    assert res["ok"], res.get("traceback") or res.get("error")
    return res


@pytest.mark.skipif(not BENCH.is_file(), reason="benchmarks/ not in this checkout")
def test_bench_memory_worker_and_report():
    res = _bench_worker({"kind": "memory", "dataset": "A", "dims": [24, 18, 30, 5, 3.5],
                         "convert": True})
    assert res["round_trip_exact"] and res["bytes_octree"] == 4 * res["octree_nodes"]
    assert res["layouts"]["ssbo"]["consumed"] == res["bytes_stacks"]
    spec = importlib.util.spec_from_file_location("geoshade_bench_stacks_test", BENCH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    other = "<!-- core:begin -->\ncore\n<!-- core:end -->\n"
    text = mod.harness.replace_section(
        other, f"{mod.MARK_BEGIN}\nold\n{mod.MARK_END}\n", mod.PART)
    text = mod.harness.replace_section(
        text, f"{mod.MARK_BEGIN}\nnew\n{mod.MARK_END}\n", mod.PART)
    assert other in text and "new" in text and "old" not in text


@pytest.mark.gl
@pytest.mark.skipif(not BENCH.is_file(), reason="benchmarks/ not in this checkout")
def test_bench_render_worker_reports_mrps():
    res = _bench_worker({"kind": "render", "dataset": "A", "dims": [24, 18, 30, 5, 3.5],
                         "layout": "textures", "size": [48, 40], "frames": 2})
    if "OpenGL" in res.get("error", ""):
        pytest.skip(res["error"])
    assert set(res["cameras"]) == {"top", "iso", "low", "below"}
    assert 0 < res["mrps_worst"] <= res["mrps_best"] and res["layout_bytes"] > 0
