"""The notebook view shows the same keys as every other output: title, colour bar, triad."""

from __future__ import annotations

import pytest

from geoshade.compute.grid.synthetic import synthetic_grid

pytest.importorskip("jupyter_rfb", reason="geoshade.show needs jupyter_rfb (geoshade[viewer])")


def test_the_notebook_frame_is_annotated(ctx):
    import geoshade

    w = geoshade.show(synthetic_grid(10, 8, 4, seed=2), size=(480, 360), property="PERMX")
    try:
        frame = w.get_frame()
        lay = w.stats["annotations"]
        assert frame.shape == (360, 480, 3)
        assert lay["title"][0]["text"].endswith("PERMX")
        assert lay["colorbar"]["label"] == "PERMX [mD]" and "triad" in lay
        x0, top, bw, bh = lay["colorbar"]["bbox"]
        assert (frame[top:top + bh, x0:x0 + bw] != 255).any()   # drawn into the frame
    finally:
        w.close()
