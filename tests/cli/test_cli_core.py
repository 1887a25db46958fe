"""``geoshade core render|porosity``, ``info`` and ``demo`` end to end, with the bad inputs."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

from geoshade.cli.main import main


@pytest.fixture
def raw16(tmp_path):
    """A 20×16×12 uint16 raw file, x fastest, with ~30 % of values in 1000..2000."""
    rng = np.random.default_rng(0)
    a = rng.integers(0, 4000, (12, 16, 20)).astype(np.uint16)
    p = tmp_path / "vol.raw"
    a.tofile(p)
    return p, a


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


SHAPE = ("--shape", 20, 16, 12, "--dtype", "uint16")


@pytest.mark.gl
@pytest.mark.parametrize("method", ["auto", "trefoil", "raycast"])
def test_render_writes_png_and_stats(capsys, tmp_path, raw16, method):
    path, a = raw16
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc, text, err = run(capsys, "core", "render", path, *SHAPE, "--select", 1000, 2000,
                        "--method", method, "--size", "80x60", "--frames", 2, "-o", out,
                        "--stats", stats)
    assert rc == 0, err
    img = np.asarray(Image.open(out))
    assert img.shape == (60, 80, 4)
    s = json.loads(stats.read_text())
    for key in ("width", "height", "method", "frame_ms", "gpu_bytes", "voxels_selected",
                "voxels_drawn", "triangles"):
        assert key in s
    assert s["width"] == 80 and s["height"] == 60
    assert s["voxels_selected"] == int(((a >= 1000) & (a <= 2000)).sum())
    assert s["method"] == ("raycast" if method == "auto" else method)
    assert str(out) in text


@pytest.mark.gl
def test_old_range_flag_still_selects_with_a_warning(capsys, tmp_path, raw16):
    """--range is the deprecated name of --select: same voxels, one warning line."""
    path, a = raw16
    stats = tmp_path / "s.json"
    rc, _, err = run(capsys, "core", "render", path, *SHAPE, "--range", 1000, 2000, "--size",
                     "32x24", "--frames", 1, "-o", tmp_path / "o.png", "--stats", stats)
    assert rc == 0, err
    assert json.loads(stats.read_text())["voxels_selected"] == int(((a >= 1000)
                                                                     & (a <= 2000)).sum())
    assert err.strip() == "geoshade: warning: range is deprecated: use select"


@pytest.mark.gl
def test_render_box_top_ortho_transparent(capsys, tmp_path, raw16):
    path, _a = raw16
    out = tmp_path / "top.png"
    rc, _, err = run(capsys, "core", "render", path, *SHAPE, "--select", 3990, 3999, "--box",
                     2, 3, 1, 10, 8, 6, "--view", "top", "--ortho", "--transparent",
                     "--no-annotations", "--size", "100x80", "-o", out)
    assert rc == 0, err
    alpha = np.asarray(Image.open(out))[..., 3]
    assert 0 < (alpha > 0).mean() < 1 and set(np.unique(alpha)) <= {0, 255}


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (("--shape", 20, 16, 13, "--dtype", "uint16"), "bytes"),
        (("--shape", 20, 16, 12, "--dtype", "uint17"), "uint17"),
        ((*SHAPE, "--select", 2000, 1000), "LO <= HI"),
        ((*SHAPE, "--select", 0, 70000), "outside uint16"),
        ((*SHAPE, "--select", 0, 100, "--box", 15, 0, 0, 10, 4, 4), "outside the volume"),
        ((*SHAPE, "--select", 0, 100, "--box", 0, 0, 0, 0, 4, 4), "empty"),
        # what fits in the GPU's memory is known once the selection is built for a context
        pytest.param((*SHAPE, "--select", 0, 4000, "--method", "trefoil", "--gpu-memory", "2K"),
                     "fits", marks=pytest.mark.gl),
    ],
)
def test_render_bad_input_one_line(capsys, tmp_path, raw16, args, expect):
    path, _ = raw16
    out = tmp_path / "bad.png"
    rc, _, err = run(capsys, "core", "render", path, *args, "--size", "32x32", "-o", out)
    assert rc != 0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
    assert expect in lines[0]
    assert "Traceback" not in err
    assert not out.exists()


def test_truncated_raw_names_file(capsys, tmp_path, raw16):
    path, _a = raw16
    short = tmp_path / "short.raw"
    short.write_bytes(path.read_bytes()[:-100])
    rc, _, err = run(capsys, "core", "render", short, *SHAPE, "-o", tmp_path / "x.png")
    assert rc != 0 and "short.raw" in err and len(err.strip().splitlines()) == 1


@pytest.mark.gl
def test_empty_selection_is_a_warning_not_an_error(capsys, tmp_path, raw16):
    path, _ = raw16
    out = tmp_path / "empty.png"
    rc, _, err = run(capsys, "core", "render", path, *SHAPE, "--select", 5000, 6000, "--size",
                     "32x24", "--transparent", "--no-annotations", "-o", out)
    assert rc == 0
    assert "empty selection" in err
    assert not np.asarray(Image.open(out))[..., 3].any()


def test_porosity_outputs(capsys, tmp_path, raw16):
    path, a = raw16
    png, csv, js = tmp_path / "p.png", tmp_path / "p.csv", tmp_path / "p.json"
    rc, _text, err = run(capsys, "core", "porosity", path, *SHAPE, "--select", 0, 1000, "--axis",
                        "x", "-o", png, "--csv", csv, "--json", js)
    assert rc == 0, err
    d = json.loads(js.read_text())
    sel = a <= 1000
    assert d["porosity"] == pytest.approx(sel.mean(), abs=0)
    np.testing.assert_array_equal(d["profile"], sel.mean(axis=(0, 1)))
    assert len(csv.read_text().strip().splitlines()) >= 20
    assert Image.open(png).size[0] > 100


@pytest.mark.gl
def test_info_file_and_gl(capsys, raw16):
    path, _ = raw16
    rc, text, err = run(capsys, "info", path, *SHAPE, "--json")
    assert rc == 0, err
    d = json.loads(text)
    assert d["shape_xyz"] == [20, 16, 12] and d["dtype"] == "uint16"
    rc, text, err = run(capsys, "info", "--gl")
    assert rc == 0 and "max tessellation level" in text and "max 3D texture size" in text


def test_missing_file(capsys, tmp_path):
    rc, _, err = run(capsys, "info", tmp_path / "nope.tif")
    assert rc != 0 and "nope.tif" in err and len(err.strip().splitlines()) == 1


@pytest.mark.gl
def test_demo_small(capsys, tmp_path):
    rc, text, err = run(capsys, "demo", "-o", tmp_path / "demo", "--voxels", 32, "--size",
                        "96x72")
    assert rc == 0, err
    pngs = sorted((tmp_path / "demo").glob("*.png"))
    assert len(pngs) >= 5
    assert "porosity-z.png" in text
    for p in pngs:
        img = np.asarray(Image.open(p).convert("RGB"))
        assert img.std() > 1, p  # something was drawn


def test_no_opengl_is_one_clear_line(tmp_path, raw16):
    import os
    import subprocess
    import sys

    path, _ = raw16
    env = dict(os.environ, GEOSHADE_GL_BACKEND="no-such-backend")
    r = subprocess.run([sys.executable, "-m", "geoshade.cli.main", "core", "render", str(path),
                        *map(str, SHAPE), "-o", str(tmp_path / "x.png")],
                       env=env, capture_output=True, text=True)
    assert r.returncode == 3
    assert r.stderr.strip().startswith("geoshade: error: no OpenGL >= 4.3")
    assert len(r.stderr.strip().splitlines()) == 1
