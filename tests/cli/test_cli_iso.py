"""``geoshade iso render|animate`` end to end, with one clear line for each bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

from geoshade.cli.main import main
from geoshade.compute.mesh import marching_cubes as mc
from geoshade.compute.mesh.displacement import displacement_field

pytestmark = pytest.mark.gl
REEK_EGRID = "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"
STATS_KEYS = ("width", "height", "method", "frame_ms", "gpu_bytes", "cells", "triangles")


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A 4-step synthetic displacement saved as .npz (SWAT + PRESSURE)."""
    f = displacement_field((30, 22, 20), steps=4, seed=3)
    sw = np.stack([f.step(k) for k in range(4)])
    p = np.stack([f.property_step("PRESSURE", k) for k in range(4)])
    path = tmp_path_factory.mktemp("iso") / "disp.npz"
    np.savez(path, SWAT=sw, PRESSURE=p)
    return path, sw


def test_render_png_stats_and_mesh(capsys, tmp_path, case):
    meshio = pytest.importorskip("meshio")
    path, sw = case
    out, stats, mesh = tmp_path / "o.png", tmp_path / "s.json", tmp_path / "m.ply"
    rc, text, err = run(capsys, "iso", "render", path, "--level", 0.5, "--step", 2,
                        "--color-by", "PRESSURE", "--size", "96x64", "--frames", 2,
                        "--mesh", mesh, "--stats", stats, "-o", out)
    assert rc == 0, err
    st = json.loads(stats.read_text())
    assert all(k in st for k in STATS_KEYS)
    assert (st["width"], st["height"], st["method"]) == (96, 64, "tessellation")
    assert st["cells"] == 29 * 21 * 19
    assert st["triangles"] == mc.triangle_count(sw[2], 0.5) > 0
    assert st["step"] == 2 and st["color_by"] == "PRESSURE"
    assert Image.open(out).size == (96, 64)
    m = meshio.read(mesh)
    assert len(m.cells_dict["triangle"]) == st["triangles"]
    assert f"{st['triangles']:,} triangles" in text and "step 2 of 4" in text


@pytest.mark.parametrize("flag", [None, "--no-mesh-cache", "--paper"])
def test_render_mesh_cache_flags(capsys, tmp_path, case, flag):
    """On by default, off with --no-mesh-cache and --paper (pictures: tests/gl/test_isosurface)."""
    path, sw = case
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    extra = [flag] if flag else []
    rc, _, err = run(capsys, "iso", "render", path, "--level", 0.5, "--step", 1, "--size",
                     "96x64", "--frames", 4, "--stats", stats, "-o", out, *extra)
    assert rc == 0, err
    st = json.loads(stats.read_text())
    assert st["mesh_cache"] is (flag is None)
    assert st["triangles"] == mc.triangle_count(sw[1], 0.5) > 0
    assert Image.open(out).size == (96, 64)


@pytest.mark.parametrize(("args", "message"), [
    (("--step", 9), "disp.npz: step 9 does not exist; there are 4 steps (0..3"),
    (("--keyword", "SGAS"), "array 'SGAS' not found; it holds SWAT, PRESSURE"),
    (("--color-by", "SOIL"), "array 'SOIL' not found"),
    (("--size", "12xq"), "size: expected WIDTHxHEIGHT"),
])
def test_bad_inputs_one_line(capsys, tmp_path, case, args, message):
    rc, _, err = run(capsys, "iso", "render", case[0], "--level", 0.5, *args,
                     "-o", tmp_path / "o.png")
    assert rc == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], err
    assert not (tmp_path / "o.png").exists()


def test_level_outside_the_values_warns_and_draws_nothing(capsys, tmp_path, case):
    out = tmp_path / "o.png"
    rc, _, err = run(capsys, "iso", "render", case[0], "--level", 2, "--size", "40x30",
                     "--no-annotations", "-o", out, "--stats", tmp_path / "s.json")
    assert rc == 0
    assert "warning: SWAT at step 3" in err and "level 2 is outside the values" in err
    assert (np.asarray(Image.open(out))[..., :3] == 255).all()
    assert json.loads((tmp_path / "s.json").read_text())["triangles"] == 0


def test_nan_cells_and_mismatched_steps(capsys, tmp_path, case):
    sw = case[1].copy()
    sw[:, 3:5, 4:6, 5:9] = np.nan
    p = tmp_path / "nan.npy"
    np.save(p, sw)
    rc, _, err = run(capsys, "iso", "render", p, "--level", 0.5, "--size", "40x30",
                     "-o", tmp_path / "o.png")
    assert rc == 0 and "16 nodes are NaN or infinite; they are treated as outside" in err
    bad = tmp_path / "bad.npz"
    np.savez(bad, SWAT=case[1], PRESSURE=np.zeros((4, 20, 22, 31)))
    rc, _, err = run(capsys, "iso", "render", bad, "--level", 0.5, "--color-by", "PRESSURE",
                     "-o", tmp_path / "o2.png")
    assert rc == 2 and "PRESSURE: shape (20, 22, 31)" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_animate_every_step(capsys, tmp_path, case, suffix):
    out = tmp_path / f"a{suffix}"
    rc, text, err = run(capsys, "iso", "animate", case[0], "--level", 0.5, "--size", "64x48",
                        "--fps", 2, "-o", out, "--stats", tmp_path / "s.json")
    assert rc == 0, err
    st = json.loads((tmp_path / "s.json").read_text())
    assert st["frames"] == 4 and st["steps"] == [0, 1, 2, 3]
    assert st["triangles"] == [mc.triangle_count(case[1][k], 0.5) for k in range(4)]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([out.name, "s.json"])
    if suffix == ".gif":
        with Image.open(out) as im:
            assert im.n_frames == 4 and im.size == (64, 48)
    else:
        iio = pytest.importorskip("imageio.v2")
        frames = iio.mimread(out)
        assert len(frames) == 4 and frames[0].shape[:2] == (48, 64)
    assert "4 steps at 64x48" in text


def test_animate_rejects_unknown_format(capsys, tmp_path, case):
    rc, _, err = run(capsys, "iso", "animate", case[0], "--level", 0.5, "-o", tmp_path / "a.avi")
    assert rc == 2 and "a.avi: -o: expected a name ending in .mp4 or .gif" in err


def test_demo_writes_two_iso_steps(capsys, tmp_path):
    rc, text, err = run(capsys, "demo", "-o", tmp_path, "--voxels", 16, "--size", "64x48")
    assert rc == 0, err
    a = np.asarray(Image.open(tmp_path / "iso-swat-step2.png"))
    b = np.asarray(Image.open(tmp_path / "iso-swat-step7.png"))
    assert a.shape == b.shape == (48, 64, 4) and not np.array_equal(a, b)
    st = json.loads((tmp_path / "iso-stats.json").read_text())
    assert st["step7"]["triangles"] > st["step2"]["triangles"] > 0
    assert "iso SWAT = 0.5" in text


@pytest.mark.data
def test_reek_render_and_missing_keyword(capsys, tmp_path, shared_data):
    egrid = shared_data / REEK_EGRID
    rc, _text, err = run(capsys, "iso", "render", egrid, "--level", 0.5, "--step", 36,
                        "--color-by", "PRESSURE", "--size", "80x60", "--frames", 1,
                        "--stats", tmp_path / "s.json", "-o", tmp_path / "r.png")
    assert rc == 0, err
    st = json.loads((tmp_path / "s.json").read_text())
    assert st["nsteps"] == 37 and st["time"] == "2003-01-01" and st["triangles"] > 1000
    assert st["inactive"] == 40 * 64 * 14 - 35817
    rc, _, err = run(capsys, "iso", "render", egrid, "--level", 0.5, "--keyword", "SOIL_X",
                     "-o", tmp_path / "x.png")
    assert rc == 2 and "keyword SOIL_X is not in the restart file" in err
    assert len(err.strip().splitlines()) == 1


BENCH = __import__("pathlib").Path(__file__).resolve().parents[2] / "benchmarks" / "bench_iso.py"


@pytest.mark.skipif(not BENCH.is_file(), reason="benchmarks/ not in this checkout")
@pytest.mark.parametrize("kind", ["geoshade", "vtk"])
def test_bench_worker_smallest_config(kind):
    """``geoshade bench iso`` is not a test; this checks that its worker reports the fields."""
    import subprocess
    import sys

    if kind == "vtk":
        pytest.importorskip("pyvista")
    cfg = {"kind": kind, "method": "default", "n": 16, "size": [64, 48], "frames": 2}
    proc = subprocess.run([sys.executable, str(BENCH), "--worker", json.dumps(cfg)],
                          capture_output=True, text=True, timeout=120)
    res = json.loads([ln for ln in proc.stdout.splitlines() if ln.startswith("{")][-1])
    assert res["ok"], res.get("traceback") or res.get("error")
    for key in ("triangles", "first_frame_ms", "rerender_ms", "step_switch_ms", "peak_rss_mib"):
        assert res[key] is not None and res[key] >= 0, key
    f = displacement_field((16, 16, 16), steps=3, seed=0)
    assert res["triangles"] == mc.triangle_count(f.step(1), 0.5)  # VTK's count too, here
    if kind == "geoshade":
        assert res["prefetched"] and res["gpu_bytes"] > 0


@pytest.mark.data
@pytest.mark.gl
def test_a_step_by_report_number_from_an_eclipse_case(capsys, tmp_path, shared_data):
    """``--step R20`` names report 20 in iso render as in grid render (the field carries the
    case's report numbers)."""
    out, stats = tmp_path / "r.png", tmp_path / "r.json"
    rc, _, err = run(capsys, "iso", "render", shared_data / REEK_EGRID, "--level", 0.5,
                     "--step", "R20", "--size", "96x64", "-o", out, "--stats", stats)
    assert rc == 0, err
    st = json.loads(stats.read_text())
    assert st["step"] == 20 and "report 20" in st["step_label"]
