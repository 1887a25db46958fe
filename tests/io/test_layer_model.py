"""Layer models (top/bottom surfaces per layer, netCDF or zarr) as stack models (issue 31, item 3).

Files made here in both layouts real models use: REGIS-style ``top``/``bottom (layer, y, x)``
with layer names, gaps, a layer that pinches out (top == bottom), a hole of NaN, y stored north
first; MODFLOW-style ``top (y, x)`` + ``botm (layer, y, x)``. Oracle: numpy over the arrays
written (each column's layer thickness and the heights its intervals start at).
"""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.errors import InputError
from geoshade.io import formats
from geoshade.io.layers.layer_model import is_layer_model, layer_intervals, read_layer_model
from geoshade.models.stacks import EMPTY

xr = pytest.importorskip("xarray")
pytest.importorskip("netCDF4")

NAMES = ["HLc", "BXz1", "KRz1", "KRk1", "DRz1"]
NX, NY = 12, 9
X = 150000.0 + 100 * np.arange(NX) + 50
Y = 460000.0 + 100 * np.arange(NY) + 50


def _surfaces():
    """(top, bottom) (K, ny, nx), y south first, with a gap, a pinch-out and a hole."""
    i, j = np.meshgrid(np.arange(NX), np.arange(NY))
    cur = 5 + np.sin(i / 3.0) + 0.5 * np.cos(j / 2.0)
    tops, bots = [], []
    for k, t in enumerate([3.0, 8.0, 15.0, 5.0, 30.0]):
        thick = t * (1 + 0.3 * np.sin((i + k) / 2.0))
        if k == 3:
            thick = np.where(i < 5, 0.0, thick)                 # pinches out: top == bottom
        top, bot = cur.copy(), cur - thick
        if k == 1:
            hole = (i - 6) ** 2 + (j - 4) ** 2 < 5
            top[hole], bot[hole] = np.nan, np.nan              # missing
        tops.append(top)
        bots.append(bot)
        cur = bot - (2.0 if k == 2 else 0.0)                   # a 2 m gap under KRz1
    return np.stack(tops), np.stack(bots)


def _regis(path, top, bot, positive=None):
    attrs = {"units": "m", **({"positive": positive} if positive else {})}
    ds = xr.Dataset({"top": (("layer", "y", "x"), top[:, ::-1], attrs),
                     "bottom": (("layer", "y", "x"), bot[:, ::-1], attrs)},
                    coords={"layer": NAMES, "x": X, "y": Y[::-1]})   # north first
    ds.attrs["crs"] = "EPSG:28992"
    ds.to_netcdf(path)
    return path


def _intervals(m):
    """Per column: [(code, bottom height, top height)] of its material intervals."""
    z = lambda lv: m.origin[2] + float(lv) * m.spacing[2]   # noqa: E731
    out = []
    for c in range(m.ncols):
        a, b = m.offsets[c], m.offsets[c + 1]
        ends = [*m.starts[a + 1:b], m.nlevels]
        out.append([(int(m.codes[i]), z(m.starts[i]), z(ends[i - a])) for i in range(a, b)
                    if m.codes[i] != EMPTY])
    return out


def test_regis_layers_are_the_files_thicknesses(tmp_path):
    top, bot = _surfaces()
    m = read_layer_model(_regis(tmp_path / "r.nc", top, bot))
    assert m.legend.names == tuple(NAMES) and m.legend.codes.tolist() == [1, 2, 3, 4, 5]
    assert m.shape == (NX, NY) and m.crs == "EPSG:28992" and m.unit == "m"
    assert m.origin[:2] == (150000.0, 460000.0) and m.spacing[:2] == (100.0, 100.0)
    cols = _intervals(m)
    thick = top - bot
    for c, runs in enumerate(cols):
        j, i = divmod(c, NX)
        want = [(k + 1, bot[k, j, i], top[k, j, i]) for k in range(len(NAMES))[::-1]
                if np.isfinite(thick[k, j, i]) and thick[k, j, i] > 0]
        assert [r[0] for r in runs] == [w[0] for w in want], c
        for (_, b0, t0), (_, b1, t1) in zip(runs, want, strict=True):
            assert b0 == pytest.approx(b1, abs=1e-4) and t0 == pytest.approx(t1, abs=1e-4)
    absent = int((~(np.isfinite(thick) & (thick > 0))).sum())
    assert m.meta["absent"] == absent and m.meta["layout"] == "top/bottom"


def test_gaps_between_layers_are_empty(tmp_path):
    top, bot = _surfaces()
    m = read_layer_model(_regis(tmp_path / "r.nc", top, bot))
    c = 0    # the gap of 2 m under KRz1 (code 3) in the first column
    a, b = m.offsets[c], m.offsets[c + 1]
    codes = m.codes[a:b].tolist()
    k3 = codes.index(3)
    assert codes[k3 - 1] == EMPTY
    gap = (m.starts[a + k3] - m.starts[a + k3 - 1]) * m.spacing[2]
    assert gap == pytest.approx(2.0, abs=1e-4)
    assert codes[-1] == EMPTY    # air over the top layer


def test_positive_down_depths_are_heights(tmp_path):
    top, bot = _surfaces()
    up = read_layer_model(_regis(tmp_path / "u.nc", top, bot))
    down = read_layer_model(_regis(tmp_path / "d.nc", -top, -bot, positive="down"))
    for a, b in zip(_intervals(up), _intervals(down), strict=True):
        assert [r[0] for r in a] == [r[0] for r in b]
        np.testing.assert_allclose([r[1:] for r in a], [r[1:] for r in b], atol=1e-4)
    assert any("positive down" in n for n in down.meta["notes"])


def test_modflow_top_and_botm(tmp_path):
    top, bot = _surfaces()
    filled = np.where(np.isnan(bot), np.nanmean(bot, axis=(1, 2), keepdims=True), bot)
    botm = np.minimum.accumulate(filled, axis=0)                 # MODFLOW: never rising
    first = top[0]
    ds = xr.Dataset({"top": (("y", "x"), first), "botm": (("layer", "y", "x"), botm)},
                    coords={"x": X, "y": Y, "layer": np.arange(len(NAMES))})
    ds.to_netcdf(tmp_path / "mf.nc")
    m = read_layer_model(tmp_path / "mf.nc")
    assert m.meta["layout"] == "top + botm" and m.unit == "m (assumed)"
    tops = np.concatenate([first[None], botm[:-1]])
    for c, runs in enumerate(_intervals(m)):
        j, i = divmod(c, NX)
        want = [(k + 1, botm[k, j, i], tops[k, j, i]) for k in range(len(NAMES))[::-1]
                if tops[k, j, i] > botm[k, j, i]]
        assert [r[0] for r in runs] == [w[0] for w in want]
        np.testing.assert_allclose([r[1:] for r in runs], [w[1:] for w in want], atol=1e-4)


def test_overlapping_layers_are_cut_to_the_upper_one(tmp_path):
    t = np.array([[[10.0]], [[9.0]]])      # layer 2 starts above layer 1's bottom (8)
    b = np.array([[[8.0]], [[5.0]]])
    ds = xr.Dataset({"top": (("layer", "y", "x"), np.repeat(np.repeat(t, 2, 1), 2, 2)),
                     "bottom": (("layer", "y", "x"), np.repeat(np.repeat(b, 2, 1), 2, 2))},
                    coords={"x": [0.5, 1.5], "y": [0.5, 1.5]})
    ds.to_netcdf(tmp_path / "o.nc")
    with pytest.warns(UserWarning, match="4 layer cells .* cut"):
        m = read_layer_model(tmp_path / "o.nc")
    assert _intervals(m)[0] == [(2, pytest.approx(5.0), pytest.approx(8.0)),
                                (1, pytest.approx(8.0), pytest.approx(10.0))]


def test_layer_intervals_against_a_loop():
    rng = np.random.default_rng(3)
    top = rng.uniform(0, 100, (6, 300))
    bot = top - rng.uniform(-2, 20, (6, 300))
    top[rng.random((6, 300)) < 0.1] = np.nan
    off, starts, codes, _ = layer_intervals(top, bot, -50.0, 0.5)
    for c in range(300):
        ceiling, want = np.inf, []
        for k in range(6):
            t, b = top[k, c], bot[k, c]
            if not (np.isfinite(t) and np.isfinite(b)):
                continue
            t = min(np.float32((t + 50) / 0.5), ceiling)
            b = min(np.float32((b + 50) / 0.5), t)
            if t > b:
                want.append((b, k + 1, t))
                ceiling = b
        got = list(zip(starts[off[c]:off[c + 1]].tolist(), codes[off[c]:off[c + 1]].tolist(),
                       strict=True))
        mats = [(s, k) for s, k in got if k != EMPTY]
        assert mats == [(float(b), k) for b, k, _ in reversed(want)], c
        assert all(np.diff([s for s, _ in got]) > 0)


@pytest.mark.filterwarnings("ignore:The data type")
def test_load_convert_and_the_format_table(tmp_path):
    import geoshade
    from geoshade.stacks import convert

    top, bot = _surfaces()
    p = _regis(tmp_path / "r.nc", top, bot)
    assert is_layer_model(p) and formats.find(p).name == "layer-model"
    assert formats.find(p, sniff=False).name == "geotop"        # by name alone: .nc
    m = geoshade.load(p)
    assert type(m).__name__ == "StackModel" and m.meta["format"] == "layer-model"
    assert convert(p).nintervals == m.nintervals
    pytest.importorskip("zarr")
    xr.open_dataset(p).to_zarr(tmp_path / "r.zarr", consolidated=False)
    z = convert(tmp_path / "r.zarr")
    assert z.nintervals == m.nintervals and np.array_equal(z.starts, m.starts)


def test_not_a_layer_model_is_one_line(tmp_path):
    xr.Dataset({"kh": (("layer", "y", "x"), np.zeros((2, 2, 2)))}).to_netcdf(tmp_path / "k.nc")
    with pytest.raises(InputError, match=r"no layer model: expected a top variable"):
        read_layer_model(tmp_path / "k.nc")
    top = np.full((2, 2, 2), np.nan)
    xr.Dataset({"top": (("layer", "y", "x"), top), "bot": (("layer", "y", "x"), top)},
               coords={"x": [0.0, 1.0], "y": [0.0, 1.0]}).to_netcdf(tmp_path / "n.nc")
    with pytest.raises(InputError, match="no layer has a thickness"):
        read_layer_model(tmp_path / "n.nc")
    xr.Dataset({"top": (("layer", "y", "x"), np.ones((1, 2, 3))),
                "bot": (("layer", "y", "x"), np.zeros((1, 2, 3)))},
               coords={"x": [0.0, 1.0, 5.0], "y": [0.0, 1.0]}).to_netcdf(tmp_path / "u.nc")
    with pytest.raises(InputError, match="'x' is not evenly spaced"):
        read_layer_model(tmp_path / "u.nc")
