"""The stacks panel on a model made from a DEM: the top (smooth/flat) and a georeferenced
drape, whose coverage the read-out says."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
rasterio = pytest.importorskip("rasterio", reason="the geo extra (rasterio) is not installed")


def _picture(win):
    win.wait_idle()
    return win.session.image.copy()


def test_top_and_georeferenced_drape_from_the_panel(window, tmp_path):
    from affine import Affine

    import geoshade.stacks as st

    y, x = np.mgrid[0:20, 0:24]
    z = (30 + 5 * np.sin(x / 4.0) + 3 * np.cos(y / 3.0)).astype(np.float32)
    dem = tmp_path / "dem.tif"
    with rasterio.open(dem, "w", driver="GTiff", width=24, height=20, count=1, dtype="float32",
                       crs="EPSG:28992", transform=Affine(10, 0, 0, 0, -10, 200)) as dst:
        dst.write(z, 1)
    ortho = tmp_path / "ortho.tif"                 # the east half of the model, red
    img = np.zeros((3, 20, 12), np.uint8)
    img[0] = 255
    with rasterio.open(ortho, "w", driver="GTiff", width=12, height=20, count=3, dtype="uint8",
                       crs="EPSG:28992", transform=Affine(10, 0, 120, 0, -10, 200)) as dst:
        dst.write(img)
    with pytest.warns(UserWarning, match=r"covers 50\.0 %"):
        window.open(st.convert(dem), "stacks", None, {"exaggeration": 3.0, "drape": ortho})
        window.wait_idle()
    assert not window.errors, window.errors
    entry = window.active
    ctl = entry.panel.controls
    assert ctl["top"].currentText() == "auto" and entry.session.stats["top"] == "smooth"
    smooth = _picture(window)
    ctl["top"].choose("flat")
    flat = _picture(window)
    assert entry.session.view.options.top == "flat" and entry.session.stats["top"] == "flat"
    assert not np.array_equal(smooth, flat)
    ctl["top"].choose("auto")
    _picture(window)
    assert entry.session.stats["drape"] and ctl["drape"].isChecked()
    ctl["drape"].setChecked(False)
    _picture(window)
    assert not entry.session.stats["drape"]
    with pytest.warns(UserWarning, match=r"covers 50\.0 %"):   # the picture it opened with
        ctl["drape"].setChecked(True)
        _picture(window)
    assert entry.session.stats["drape"] and entry.session.stats["drape_covered"] == 0.5
    assert "drape over 50 % of the model" in window.readout.text()
