"""Issue 33 item 3, the isosurface part: ``--diff STEP`` draws the isosurface of
FIELD(step) − FIELD(STEP) on the active cells (ΔSWAT = 0.2).

Oracles: resfo's SWAT records of the real OPM Flow run of Reek (shared data) made into the
masked difference by numpy, scikit-image's lorensen marching cubes on it (its triangle count is
the View's), numpy's min/max over the active cells (``value_range``); the steps paired by date,
a static keyword and a field of one step refused in one line; ``iso render --diff`` writes the
picture and the stats; ``update(diff=...)`` draws what opening with it draws.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import geoshade
from geoshade.compute.mesh import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.iso import IsoView
from geoshade.iso.diff import assumed_level, difference_field
from geoshade.models import FieldSeries
from tests.compute.test_marching_cubes_open import skimage_masked, whole_cell_count

#: the Reek deck simulated by OPM Flow (shared data: ``<repo>/../shared/data``)
REEK = (Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "reek_cornerpoint"
        / "opm_flow_run" / "2_R001_REEK-0").resolve()


def reek_run(test):
    return pytest.mark.data(pytest.mark.skipif(
        not REEK.with_suffix(".UNRST").exists(),
        reason="the Reek OPM Flow run (shared data) is absent")(test))

quiet = pytest.mark.filterwarnings("ignore::UserWarning")


def _reek_arrays(keyword: str = "SWAT"):
    """(every report step's ``keyword`` as (nz, ny, nx) float64 with NaN at inactive cells,
    active (nz, ny, nx) bool, dates) from resfo's reading of the EGRID and UNRST."""
    resfo = pytest.importorskip("resfo")
    egrid = {k.strip(): np.asarray(v) for k, v in resfo.read(REEK.with_suffix(".EGRID"))}
    nx, ny, nz = (int(v) for v in egrid["GRIDHEAD"][1:4])
    active = egrid["ACTNUM"].reshape((nx, ny, nz), order="F") > 0
    steps, dates = [], []
    for k, v in resfo.read(REEK.with_suffix(".UNRST")):
        if k.strip() == "INTEHEAD":
            d, m, y = (int(x) for x in np.asarray(v)[64:67])
            dates.append(f"{y:04d}-{m:02d}-{d:02d}")
        elif k.strip() == keyword:
            cells = np.full(nx * ny * nz, np.nan)
            cells[np.flatnonzero(active.ravel(order="F"))] = np.asarray(v, np.float64)
            steps.append(cells.reshape((nx, ny, nz), order="F").T)
    return steps, active.T, dates


def _masked_change(steps, active, k, base) -> np.ndarray:
    """The change numpy makes of two steps: float64 difference kept as float32, as drawn."""
    return (steps[k] - steps[base]).astype(np.float32)


def _scikit_image_count(d, active, level) -> int:
    """scikit-image's lorensen triangles over the cells whose 8 corners are active, of −Δ at
    −level: its table takes the nodes *above* the level as inside and this project's those
    *below* (S < S*), so on an ambiguous face the two join opposite corners; on the negated
    field they are the same table case for case (:func:`test_lorensen_is_our_table_negated`)."""
    _, whole = whole_cell_count(d, active, level)
    _, faces = skimage_masked(-d, active, -level, whole)
    return len(faces)


def test_lorensen_is_our_table_negated():
    """Every one of the 254 crossed cases: scikit-image's lorensen count on the negated cube
    equals this project's table's count (the oracle above is exact, not within ambiguity)."""
    measure = pytest.importorskip("skimage.measure")
    counts = mc.triangle_counts()
    for case in range(1, 255):
        v = np.ones((2, 2, 2), np.float32)
        for p in range(8):
            if case >> p & 1:   # corner p below the level
                v[p >> 2 & 1, p >> 1 & 1, p & 1] = 0.0
        _, faces, _, _ = measure.marching_cubes(-v, -0.5, method="lorensen",
                                                allow_degenerate=True)
        assert len(faces) == counts[case], case


def test_difference_field_is_numpys_change_on_the_active_nodes():
    rng = np.random.default_rng(4)
    s = rng.random((4, 5, 6, 7)).astype(np.float32)
    p = rng.random((4, 5, 6, 7)) * 100
    poro = rng.random((5, 6, 7))
    active = rng.random((5, 6, 7)) > 0.2
    f = FieldSeries(s, active=active, name="SWAT", properties={"PRESSURE": p, "PORO": poro})
    d = difference_field(f, 1)
    assert d.name == "ΔSWAT" and d.nsteps == 4 and d.meta["diff"] == 1
    want = (s[3].astype(np.float64) - s[1].astype(np.float64)).astype(np.float32)
    assert np.array_equal(d.step(3), want) and np.array_equal(d.active, active)
    assert d.meta["differenced"] == ["PRESSURE"]   # static PORO kept as it is
    assert np.allclose(d.property_step("PRESSURE", 2), p[2] - p[1], atol=1e-4)
    assert np.array_equal(d.property_step("PORO", 2), poro.astype(np.float32))
    assert not d.step(1).any()   # the step the change is taken from: nothing changed


@pytest.mark.gl
@reek_run
@pytest.mark.parametrize(("step", "diff", "level"), [
    (-1, "2000-01-01", 0.2), ("2001-07-01", "R0", 0.1), (-1, 12, -0.1)])
def test_reek_change_has_scikit_images_triangles_and_numpys_range(ctx, step, diff, level):
    """The OPM Flow run of Reek (35,817 of 56,320 cells active): the GPU's triangles of
    ΔSWAT = level are scikit-image's on the masked change, value_range numpy's over the active
    cells, both steps named by date in the stats and the title."""
    steps, active, dates = _reek_arrays()
    f = load_field(REEK.with_suffix(".EGRID"))
    assert f.times == dates   # the reader's dates are the file's
    with IsoView(f, level, step=step, diff=diff, size=(480, 360), annotations=True,
                 ctx=ctx) as v:
        _, st = v.draw()
    k, base = st["diff"]["step"], st["diff"]["from"]
    assert (dates[k], dates[base]) == tuple(st["diff"]["dates"])
    if isinstance(diff, str) and diff[:1] == "2":
        assert dates[base] == diff   # paired by date
    d = _masked_change(steps, active, k, base)
    assert st["triangles"] == _scikit_image_count(d, active, level) > 0
    assert st["triangles"] == whole_cell_count(d, active, level)[0]
    ref = (steps[k] - steps[base])[active]
    assert st["value_range"] == pytest.approx([ref.min(), ref.max()], rel=1e-6)
    title = " ".join(t["text"] for t in st["annotations"]["title"])
    assert f"ΔSWAT = {level:g}, {dates[k]} − {dates[base]}" in title, title


@pytest.mark.gl
@reek_run
@quiet
def test_reek_colour_by_pressure_change_is_diverging_and_symmetric(ctx):
    steps, active, _ = _reek_arrays("PRESSURE")
    f = load_field(REEK.with_suffix(".EGRID"), color_by=["PRESSURE", "PORO"])
    with IsoView(f, 0.2, diff=0, color_by="PRESSURE", size=(480, 360), annotations=True,
                 ctx=ctx) as v:
        _, st = v.draw()
        dp = (steps[-1] - steps[0])[active]
        m = float(np.abs(dp).max())
        assert st["color_range"] == pytest.approx([-m, m], rel=1e-5)   # centred on 0
        assert st["colormap"] == "RdBu_r" and st["log"] is False
        assert st["annotations"]["colorbar"]["label"] == "ΔPRESSURE [bar]"
        v.update(color_range=(-50, 50))   # a range given is kept
        _, st = v.draw()
        assert st["color_range"] == [-50, 50]
        v.update(color_by="PORO", color_range=None)   # a static quantity: as it is
        _, st = v.draw()
        assert st["colormap"] == "viridis"
        assert st["annotations"]["colorbar"]["label"].startswith("PORO")


def _npz(tmp_path, times=("2000-01-01", "2000-07-01", "2001-01-01", "2001-07-01")):
    """A (t, z, y, x) saturation front with its dates, and its pressure."""
    z, y, x = np.mgrid[0:10, 0:12, 0:14].astype(np.float64)
    s = np.stack([np.clip((x - 2.3 - 2.7 * t - 0.21 * z) * -0.19 + 0.6, 0.1, 0.9)
                  + 0.0137 * y * (1 + t) for t in range(len(times))]).astype(np.float32)
    path = tmp_path / "front.npz"
    np.savez(path, SWAT=s, PRESSURE=(200.0 - s * 50).astype(np.float32),
             times=np.array(times))
    return path, s


@pytest.mark.gl
def test_steps_paired_by_date_never_by_position(ctx, tmp_path):
    """A date names the step with that date; an index names its date in the stats and the
    title; a date the field lacks, or a date on a field without dates, is one line."""
    path, s = _npz(tmp_path)
    f = load_field(path)
    common = dict(step="2001-07-01", size=(160, 120), ctx=ctx)
    with IsoView(f, 0.2, diff="2000-07-01", **common) as a:
        img_a, st_a = a.draw()
    with IsoView(f, 0.2, diff=1, **common) as b:
        img_b, st_b = b.draw()
    assert st_a["diff"] == st_b["diff"] == {
        "step": 3, "from": 1, "dates": ["2001-07-01", "2000-07-01"],
        "labels": ["step 3 (2001-07-01)", "step 1 (2000-07-01)"]}
    assert np.array_equal(img_a, img_b)
    with pytest.raises(InputError, match=r"step 2000-02-01: no step has that date; the steps "
                                         r"run from 2000-01-01 to 2001-07-01"):
        geoshade.view(f, diff="2000-02-01", ctx=ctx)
    np.save(tmp_path / "undated.npy", s)
    with pytest.raises(InputError, match=r"step 2000-07-01: the steps have no dates here; "
                                         r"give an index"):
        geoshade.view(load_field(tmp_path / "undated.npy"), diff="2000-07-01", ctx=ctx)
    hourly = FieldSeries(s, name="SWAT", times=["2015-01-01 00:00", "2015-01-01 06:00",
                                                "2015-01-01 12:00", "2015-01-02 00:00"])
    with pytest.raises(InputError, match=r"3 steps have that date .* give the time too"):
        geoshade.view(hourly, diff="2015-01-01", ctx=ctx)
    with IsoView(hourly, 0.2, diff="2015-01-01 06:00", size=(64, 48), ctx=ctx) as h:
        assert h.draw()[1]["diff"]["from"] == 1


@pytest.mark.gl
def test_zarr_field_change_equals_scikit_image(ctx, tmp_path):
    zarr = pytest.importorskip("zarr")
    _, s = _npz(tmp_path)
    store = tmp_path / "front.zarr"
    arr = zarr.open(str(store), mode="w", shape=s.shape, dtype="f4", chunks=(1, *s.shape[1:]))
    arr[:] = s
    arr.attrs["times"] = ["2000-01-01", "2000-07-01", "2001-01-01", "2001-07-01"]
    f = load_field(store)
    with IsoView(f, 0.3, step=-1, diff="2000-01-01", size=(160, 120), ctx=ctx) as v:
        _, st = v.draw()
    d = (s[3].astype(np.float64) - s[0].astype(np.float64)).astype(np.float32)
    act = np.ones(d.shape, bool)
    assert st["triangles"] == _scikit_image_count(d, act, 0.3) > 0
    assert st["value_range"] == pytest.approx([float(d.min()), float(d.max())])


def test_static_keyword_and_one_step_refuse_in_one_line(tmp_path):
    np.save(tmp_path / "one.npy", np.zeros((3, 4, 5), np.float32))
    with pytest.raises(InputError, match=r"^diff: one of .*one\.npy has one step; a "
                                         r"difference needs two") as err:
        geoshade.view(load_field(tmp_path / "one.npy"), diff=0)
    assert "\n" not in str(err.value)
    from geoshade.compute.grid.synthetic import synthetic_grid

    g = synthetic_grid(6, 5, 3)
    with pytest.raises(InputError, match=r"^diff: PORO is a static keyword \(the same at every "
                                         r"report step\); .* such as SWAT") as err:
        geoshade.view(g, as_="iso", keyword="PORO", diff=0)
    assert "\n" not in str(err.value)


@pytest.mark.gl
@quiet
def test_update_diff_equals_opening_with_it(ctx, tmp_path):
    """Explicit level and assumed level, there and back again (the parity suite's case opens
    without a level)."""
    path, _ = _npz(tmp_path)
    f = load_field(path, color_by="PRESSURE")
    common = dict(color_by="PRESSURE", size=(200, 150), annotations=True, ctx=ctx)
    for level in (0.2, None):
        with IsoView(f, level, **common) as a:
            a.draw()
            a.update(diff="2000-01-01")
            img_a, st_a = a.draw()
            with IsoView(f, level, diff=0, **common) as b:
                img_b, st_b = b.draw()
            assert np.array_equal(img_a, img_b), level
            assert st_a["level"] == st_b["level"] and st_a["color_range"] == st_b["color_range"]
            a.update(diff=None)
            img_c, st_c = a.draw()
            with IsoView(f, level, **common) as c:
                img_d, _ = c.draw()
            assert np.array_equal(img_c, img_d) and st_c["diff"] is None


@pytest.mark.gl
def test_a_level_not_given_is_assumed_and_said(ctx, tmp_path):
    path, s = _npz(tmp_path)
    d = s[3].astype(np.float64) - s[0].astype(np.float64)
    with pytest.warns(UserWarning, match=r"level ΔSWAT = .* assumed: half the largest change "
                                         r"of 2001-07-01 − 2000-01-01"):
        with IsoView(load_field(path), diff=0, size=(320, 240), annotations=True,
                     ctx=ctx) as v:
            _, st = v.draw()
    assert st["level"] == assumed_level(d.min(), d.max()) != 0
    assert any("assumed" in n for n in st["notes"])
    sub = st["annotations"]["title"][1]["text"]
    assert "level assumed" in sub, sub


@pytest.mark.gl
def test_the_step_of_the_change_itself_is_empty_and_says_why(ctx, tmp_path):
    from geoshade.errors import EmptySceneWarning

    path, _ = _npz(tmp_path)
    with pytest.warns(EmptySceneWarning, match=r"the shown step is the step the change is "
                                               r"taken from \(2000-07-01 − 2000-07-01\)"):
        _, st = geoshade.iso.render(load_field(path), 0.2, step=1, diff=1, size=(64, 48),
                                    frames=1, ctx=ctx)
    assert st["triangles"] == 0


@pytest.mark.gl
@reek_run
def test_cli_iso_render_diff_writes_picture_and_stats(tmp_path, capsys):
    from PIL import Image

    from geoshade.cli.main import main

    out, stats = tmp_path / "dswat.png", tmp_path / "dswat.json"
    egrid = str(REEK.with_suffix(".EGRID"))
    rc = main(["iso", "render", egrid, "--diff", "2000-01-01", "--level", "0.2",
               "--color-by", "PRESSURE", "--size", "800x600", "-o", str(out),
               "--stats", str(stats)])
    assert rc == 0, capsys.readouterr().err
    st = json.loads(stats.read_text())
    assert st["diff"]["dates"] == ["2003-01-01", "2000-01-01"] and st["name"] == "ΔSWAT"
    steps, active, _ = _reek_arrays()
    ref = (steps[-1] - steps[0])[active]
    assert st["value_range"] == pytest.approx([ref.min(), ref.max()], rel=1e-6)
    assert st["annotations"]["colorbar"]["label"] == "ΔPRESSURE [bar]"
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape == (600, 800, 3) and (np.abs(img.astype(int) - 255).sum(-1) > 30).any()
    assert "2003-01-01 − 2000-01-01" in capsys.readouterr().out
    rc = main(["iso", "render", egrid, "--keyword", "PORO", "--diff", "0", "-o",
               str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert rc == 2 and "diff: PORO is a static keyword" in err and err.count("\n") == 1, err
    assert not (tmp_path / "x.png").exists()


@pytest.mark.gl
@quiet
def test_cli_render_and_view_of_a_4d_field(tmp_path, capsys):
    """``iso render --diff`` of an .npz (t, z, y, x) writes the stats; ``view --screenshot``
    with the same flags is the same picture; a 3D .npy refuses in one line."""
    from PIL import Image

    from geoshade.cli.main import main

    pytest.importorskip("PySide6")
    path, s = _npz(tmp_path)
    flags = ["--diff", "2000-07-01", "--level", "0.3", "--color-by", "PRESSURE",
             "--size", "320x240"]
    out, stats = tmp_path / "d.png", tmp_path / "d.json"
    assert main(["iso", "render", str(path), *flags, "--frames", "1", "-o", str(out),
                 "--stats", str(stats)]) == 0, capsys.readouterr().err
    st = json.loads(stats.read_text())
    d = (s[3].astype(np.float64) - s[1].astype(np.float64)).astype(np.float32)
    assert st["triangles"] == _scikit_image_count(d, np.ones(d.shape, bool), 0.3) > 0
    assert st["diff"]["dates"] == ["2001-07-01", "2000-07-01"]
    shot = tmp_path / "v.png"
    assert main(["view", str(path), "--as", "iso", *flags, "--screenshot", str(shot)]) == 0
    assert np.array_equal(np.asarray(Image.open(shot).convert("RGB")),
                          np.asarray(Image.open(out).convert("RGB")))
    np.save(tmp_path / "one.npy", s[0])
    capsys.readouterr()
    rc = main(["iso", "render", str(tmp_path / "one.npy"), "--diff", "0", "-o",
               str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert rc == 2 and "has one step; a difference needs two" in err and \
        err.count("\n") == 1, err
