"""Smoke test of ``benchmarks/bench_core.py``: its worker, for the smallest config, prints JSON.

The benchmark itself (``geoshade bench core``) is not a test; this only checks that the worker
runs and reports every field the table and the targets read.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_core.py"
FIELDS = ("n", "method", "width", "height", "voxels_box", "voxels_selected", "voxels_drawn",
          "prepare_ms", "first_frame_ms", "rerender_ms", "range_change_ms", "box_change_ms",
          "gpu_bytes", "gpu_bytes_formula", "bytes_per_voxel", "peak_rss_mib", "coverage")

pytestmark = pytest.mark.skipif(not BENCH.is_file(), reason="benchmarks/ not in this checkout")


def _bench_module():
    spec = importlib.util.spec_from_file_location("geoshade_bench_core_test", BENCH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.gl
@pytest.mark.timeout(60)
def test_worker_smallest_config_prints_json_with_the_fields():
    cfg = {"kind": "geoshade", "n": 16, "porosity": 0.3, "seed": 0, "method": "raycast",
           "size": [64, 48], "range": [0, 19000], "range2": [0, 13500],
           "box2": [4, 4, 4, 8, 8, 8], "frames": 2}
    proc = subprocess.run([sys.executable, str(BENCH), "--worker", json.dumps(cfg)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    assert lines, f"no JSON line; stderr: {proc.stderr[-2000:]}"
    res = json.loads(lines[-1])
    if not res["ok"] and "OpenGL" in res.get("error", ""):
        pytest.skip(res["error"])
    assert res["ok"], res.get("traceback") or res.get("error")
    missing = [f for f in FIELDS if f not in res]
    assert not missing, f"worker JSON lacks {missing}"
    assert (res["width"], res["height"]) == (64, 48)
    assert res["voxels_box"] == 16**3
    assert 0 < res["voxels_selected"] < res["voxels_box"]
    assert res["gpu_bytes"] == res["gpu_bytes_formula"]  # allocated == formula
    assert res["bytes_per_voxel"] <= 1.2 * 1.5  # palette overhead at 16³
    assert res["peak_rss_mib"] > 0 and res["first_frame_ms"] > 0 and res["rerender_ms"] > 0
    assert res["range_change"]["voxels_selected"] <= res["voxels_selected"]
    assert res["box_change"]["voxels_selected"] <= res["voxels_selected"]


def test_results_section_is_replaced_in_place():
    mod = _bench_module()
    other = "<!-- stacks:begin -->\nstacks\n<!-- stacks:end -->\n"
    first = mod.harness.replace_section(
        "", f"{mod.MARK_BEGIN}\nold\n{mod.MARK_END}\n", mod.PART)
    text = mod.harness.replace_section(
        first + "\n" + other, f"{mod.MARK_BEGIN}\nnew\n{mod.MARK_END}\n", mod.PART)
    assert "new" in text and "old" not in text and other in text
    assert text.count(mod.MARK_BEGIN) == 1 and text.count(mod.MARK_END) == 1


def test_write_results_keeps_other_sections_and_the_umask_mode(tmp_path):
    import os

    mod = _bench_module()
    (tmp_path / "RESULTS.md").write_text("<!-- stacks:begin -->\nstacks\n<!-- stacks:end -->\n")
    extra = tmp_path / "x.json"
    extra.write_text("{}")
    extra.chmod(0o600)
    res = mod.harness.write_results(tmp_path, "core", f"{mod.MARK_BEGIN}\nnew\n{mod.MARK_END}\n",
                                    extra, tmp_path / "missing.png")
    text = res.read_text()
    assert "stacks" in text and "\nnew\n" in text
    umask = os.umask(0)
    os.umask(umask)
    assert (res.stat().st_mode & 0o777) == (extra.stat().st_mode & 0o777) == 0o666 & ~umask


def test_fig5_curve_uses_the_allocation_formula():
    from geoshade.compute.voxels.bitmaps import gpu_bytes_estimate

    mod = _bench_module()
    curve = mod.fig5_curve((100, 2000))
    assert curve["bytes"]["trefoil"] == [gpu_bytes_estimate((d, d, d), "trefoil")
                                         for d in (100, 2000)]
    assert curve["bytes"]["cubes"][0] == gpu_bytes_estimate((100,) * 3, "cubes", 500_000)
    assert curve["bytes"]["trefoil"][1] / 2000**3 <= 1.2
