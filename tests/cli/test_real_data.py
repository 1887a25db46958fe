"""The digital-core commands on the real micro-CT data in ../shared/data (skipped if absent)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from geoshade.cli.main import main

# both tests render
pytestmark = pytest.mark.gl


def test_berea_pore_space_render_and_porosity(shared_data, tmp_path, capsys):
    raw = shared_data / "microct_dpm_berea" / "berea_pore.raw"
    a = np.fromfile(raw, np.uint8).reshape(110, 110, 110)
    stats = tmp_path / "s.json"
    rc = main(["core", "render", str(raw), "--shape", "110", "110", "110", "--dtype", "uint8",
               "--select", "0", "0", "--size", "96x72", "--frames", "1", "-o",
               str(tmp_path / "b.png"), "--stats", str(stats)])
    assert rc == 0, capsys.readouterr().err
    s = json.loads(stats.read_text())
    assert s["voxels_selected"] == int((a == 0).sum())
    assert s["gpu_bytes"] <= 1.2 * a.size + 1100
    rc = main(["core", "porosity", str(raw), "--shape", "110", "110", "110", "--dtype", "uint8",
               "--select", "0", "0", "--box", "10", "10", "10", "50", "60", "70", "-o",
               str(tmp_path / "p.png"), "--json", str(tmp_path / "p.json")])
    assert rc == 0
    d = json.loads((tmp_path / "p.json").read_text())
    sub = a[10:80, 10:70, 10:60] == 0
    assert d["porosity"] == pytest.approx(sub.mean(), abs=0)
    np.testing.assert_array_equal(d["profile"], sub.mean(axis=(1, 2)))


def test_snow_16bit_render_matches_trefoil(shared_data, tmp_path, capsys):
    """A 16-bit range on real X-ray data: raycast and trefoil draw the same picture."""
    tif = shared_data / "microct_spam_snow" / "snow.tif"
    imgs = {}
    for method in ("raycast", "trefoil"):
        out = tmp_path / f"{method}.png"
        rc = main(["core", "render", str(tif), "--select", "20000", "40103", "--box", "20", "20",
                   "20", "48", "40", "32", "--method", method, "--size", "120x90", "--frames",
                   "1", "-o", str(out)])
        assert rc == 0, capsys.readouterr().err
        from PIL import Image

        imgs[method] = np.asarray(Image.open(out)).astype(int)
    diff = np.abs(imgs["raycast"] - imgs["trefoil"]).max(-1) > 3
    assert diff.mean() < 0.01
