"""Simulation wells of a restart file drawn by the grid view: pipes at the projected completion
cells, status following the report step, names in the annotation layout, the x-ray half-tone
inside an opaque grid; the CLI flags. The case is a small OPM Flow run
(``tests/io/opm_wells_case.py``; skipped without OPM Flow)."""

from __future__ import annotations

import json
from itertools import pairwise

import numpy as np
import pytest

import geoshade
from geoshade.errors import InputError
from geoshade.grid import GridView
from geoshade.grid.geometry import SHUT_COLOR, SIM_WELL_COLORS, cell_centres_at, world_points
from geoshade.io.grids.restart_wells import restart_wells
from tests.io.opm_wells_case import EXPECTED, opm_case

SIZE = (240, 180)
EXAG = 10.0
GREY = "#8c8c8c"


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    return opm_case(tmp_path_factory)


@pytest.fixture
def grid(case):
    return geoshade.load(case)


def project(cam, pts, size):
    """Pixel (column, row) of world points under ``cam``."""
    w, h = size
    p = np.column_stack([pts, np.ones(len(pts))]) @ (cam.projection_matrix()
                                                      @ cam.view_matrix()).T
    return np.column_stack([(p[:, 0] / p[:, 3] + 1) * 0.5 * w,
                            (1 - p[:, 1] / p[:, 3]) * 0.5 * h])


def hue(rgb) -> str:
    """Which of the well colours a pixel (or an RGB 0..1) is nearest in hue: green, blue, red
    or grey."""
    r, g, b = (float(v) for v in np.asarray(rgb, float)[:3])
    if max(r, g, b) - min(r, g, b) < 0.12 * max(r, g, b, 1e-9):
        return "grey"
    return ("red", "green", "blue")[int(np.argmax([r, g, b]))]


TYPE_HUE = {"producer": "green", "water injector": "blue", "gas injector": "red"}


def draw(ctx, grid, step, **kw):
    v = GridView(grid, size=SIZE, ctx=ctx, exaggeration=EXAG, solid_color=GREY, step=step, **kw)
    try:
        cam = v.camera(view="iso")
        img, st = v.draw(cam)
        return img, st, cam, v.wells.sim_shapes
    finally:
        v.release()


def near(img, xy, radius=2):
    """The pixels within ``radius`` of pixel ``xy`` (column, row)."""
    x, y = (round(float(v)) for v in xy)
    return img[max(0, y - radius):y + radius + 1, max(0, x - radius):x + radius + 1, :3]


def test_pipes_appear_at_the_projected_completion_cells(ctx, grid):
    bare, *_ = draw(ctx, grid, 1, sim_wells=False)
    img, st, cam2, shapes = draw(ctx, grid, 1)
    assert st["sim_wells"] == 3 and st["sim_well_completions"] == 5
    assert st["sim_well_names"] == ["PROD", "GINJ", "WINJ"]
    changed = np.any(img[..., :3] != bare[..., :3], axis=-1)
    wells = restart_wells(grid)[1]
    for w in wells:
        centres = world_points(grid, cell_centres_at(grid, w.cells), EXAG)
        for xy in project(cam2, centres, SIZE):
            px = near(img, xy)[near(changed[..., None], xy)[..., 0]]
            assert len(px), (w.name, xy)
            # the pipe's own colour (solid or half-tone inside the grid) is there
            assert TYPE_HUE[w.type] in {hue(p / 255) for p in px}, w.name
    # nothing changed away from the pipes: every changed pixel is near a projected pipe
    ys, xs = np.nonzero(changed)
    segs = [project(cam2, p, SIZE) for p in shapes.paths]
    d = np.full(len(xs), np.inf)
    q = np.column_stack([xs + 0.5, ys + 0.5])
    for s in segs:
        for a, b in pairwise(s):
            t = np.clip(((q - a) @ (b - a)) / max(float((b - a) @ (b - a)), 1e-9), 0, 1)
            d = np.minimum(d, np.linalg.norm(q - (a + t[:, None] * (b - a)), axis=1))
    assert d.max() < 8, d.max()


def test_status_follows_the_report_step(ctx, grid):
    """WINJ is shut at report step 3 and open again at 4; GINJ's second completion is shut from
    step 2: their pixels turn grey and back."""
    winj = restart_wells(grid)[1]["WINJ"]
    centre = world_points(grid, cell_centres_at(grid, winj.cells), EXAG)
    hues = {}
    stats = {}
    for k in (2, 3, 4):
        img, st, cam, _ = draw(ctx, grid, k)
        px = near(img, project(cam, centre, SIZE)[0], 1).reshape(-1, 3)
        hues[k] = {hue(p / 255) for p in px}
        stats[k] = st
    assert "blue" in hues[2] and "blue" in hues[4]
    assert "blue" not in hues[3]
    assert [stats[k]["sim_wells_open"] for k in (2, 3, 4)] == [3, 2, 3]
    assert [stats[k]["sim_well_open_completions"] for k in (2, 3, 4)] == [4, 3, 4]
    for k, wells in EXPECTED.items():
        assert set(wells) == set(draw(ctx, grid, k)[1]["sim_well_names"])


def test_step_change_through_update_rebuilds_the_pipes(ctx, grid):
    with GridView(grid, size=SIZE, ctx=ctx, step=2, exaggeration=EXAG) as v:
        first = v.wells.sim_shapes
        v.update(step=3)
        assert v.wells.sim_shapes is not first
        _, st = v.draw()
        assert st["sim_wells_open"] == 2
        v.update(sim_wells=False)
        _, st = v.draw()
        assert v.wells.sim_visual is None and "sim_wells" not in st
    assert v.gpu_bytes == 0


def test_names_in_the_annotation_layout(ctx, grid):
    with GridView(grid, size=(480, 360), ctx=ctx, step=3, exaggeration=EXAG,
                  annotations=True) as v:
        cam = v.camera()
        _, st = v.draw(cam)
        heads = project(cam.with_aspect(480 / 360), v.wells.sim_shapes.heads, (480, 360))
    labels = st["annotations"]["labels"]
    assert [lab["text"] for lab in labels] == ["PROD", "GINJ", "WINJ (shut)"]
    for lab, (x, y) in zip(labels, heads, strict=True):
        assert (lab["x"], lab["y"]) == pytest.approx((x, y), abs=0.1)
        bx, by, bw, bh = lab["bbox"]
        assert bx <= x <= bx + bw and by + bh <= y + 1   # centred above the head


def test_labels_change_only_the_pixels_they_cover():
    from geoshade.styles.annotate import Annotations, Label, annotate

    base = np.random.default_rng(0).integers(0, 255, (200, 300, 4), dtype=np.uint8)
    out, layout = annotate(base, Annotations(labels=(Label("PROD", 150, 100, (0.1, 0.6, 0.2)),
                                                     Label("OUT", 400, 10))))
    assert [lab["text"] for lab in layout["labels"]] == ["PROD"]   # the one inside
    bx, by, bw, bh = layout["labels"][0]["bbox"]
    diff = np.any(out != base, axis=-1)
    ys, xs = np.nonzero(diff)
    assert diff.any()
    assert xs.min() >= bx - 3 and xs.max() <= bx + bw + 3
    assert ys.min() >= by - 3 and ys.max() <= by + bh + 3


def test_xray_keeps_wells_inside_an_opaque_grid_visible(ctx, grid):
    """From the front, PROD's completions (column 8, 6: the back row) are behind the grid's
    front face: with the x-ray pass their pixels show the well's green as a half-tone (3 pixels
    in 4), without it the grey grid only."""
    w = restart_wells(grid)[1]["PROD"]
    centres = world_points(grid, cell_centres_at(grid, w.cells), EXAG)
    greens = {}
    for xray in (True, False):
        v = GridView(grid, size=SIZE, ctx=ctx, step=1, exaggeration=EXAG, solid_color=GREY,
                     well_xray=xray, view="front", ortho=True)
        try:
            cam = v.camera()
            img, _ = v.draw(cam)
        finally:
            v.release()
        greens[xray] = [sum(hue(p / 255) == "green" for p in near(img, xy, 1).reshape(-1, 3))
                        for xy in project(cam, centres, SIZE)]
    assert min(greens[True]) >= 5 and max(greens[False]) == 0, greens


def test_sim_wells_default_and_errors(ctx, grid):
    from geoshade.compute.grid.synthetic import synthetic_grid

    with GridView(grid, size=SIZE, ctx=ctx) as v:
        assert v.settings()["sim_wells"] is True and v.has_sim_wells()
    plain = synthetic_grid(4, 3, 2)
    with GridView(plain, size=SIZE, ctx=ctx) as v:
        assert v.settings()["sim_wells"] is False and not v.has_sim_wells()
    with pytest.raises(InputError, match=r"sim_wells: .* has no simulation wells: it has no "
                                         r"restart file"):
        GridView(plain, size=SIZE, ctx=ctx, sim_wells=True)
    with pytest.raises(InputError, match="sim_wells: expected"):
        GridView(grid, size=SIZE, ctx=ctx, sim_wells="often")


def test_shut_and_type_colours_are_distinct():
    hues = {t: hue(c) for t, c in SIM_WELL_COLORS.items() if t in TYPE_HUE}
    assert hues == TYPE_HUE and hue(SHUT_COLOR) == "grey"


@pytest.mark.gl
def test_cli_sim_wells_flags(case, tmp_path, capsys):
    from geoshade.cli.main import main

    stats = tmp_path / "s.json"
    rc = main(["grid", "render", str(case), "--step", "3", "--exaggeration", "10",
               "--size", "320x240", "-o", str(tmp_path / "a.png"), "--stats", str(stats)])
    assert rc == 0
    st = json.loads(stats.read_text())
    assert st["sim_wells"] == 3 and st["sim_wells_open"] == 2
    assert [lab["text"] for lab in st["annotations"]["labels"]] == ["PROD", "GINJ",
                                                                    "WINJ (shut)"]
    rc = main(["grid", "render", str(case), "--no-sim-wells", "--size", "320x240",
               "-o", str(tmp_path / "b.png"), "--stats", str(stats)])
    assert rc == 0 and "sim_wells" not in json.loads(stats.read_text())
    capsys.readouterr()


def test_viewer_grid_panel_checkbox(ctx, grid):
    """The grid panel's "sim wells" checkbox: on for a case with restart wells, toggling it
    applies ``sim_wells`` (the readout follows)."""
    import os

    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6")
    from geoshade.viewer.app import application
    from geoshade.viewer.window import ViewerWindow

    application(offscreen=True)
    win = ViewerWindow(size=(200, 150))
    win.show()
    try:
        win.open(grid, "grid", None, {"step": 3, "exaggeration": EXAG})
        win.wait_idle()
        assert not win.errors, win.errors
        box = win.active.panel.controls["sim_wells"]
        assert box.currentText() == "yes"   # on for a case with restart wells
        assert "3 sim wells (2 open)" in win.readout.text()
        box.choose(False)
        win.wait_idle()
        assert "sim wells" not in win.readout.text()
        assert win.active.session.stats.get("sim_wells") is None
    finally:
        win.close()


@pytest.mark.gl
def test_cli_wells_files_in_every_format(tmp_path, capsys):
    """``--wells`` repeated: a CSV and an RMS ASCII well drawn together on a GRDECL grid."""
    from geoshade.cli.main import main
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    case = write_grdecl(synthetic_grid(4, 3, 2), tmp_path / "case.grdecl")
    csv = tmp_path / "wells.csv"
    csv.write_text("name,x,y,z,md\nA,100,100,1500,1500\nA,100,100,1700,1700\n"
                   "B,300,200,1500,\nB,310,210,1690,\n")
    rms = tmp_path / "C.rmswell"
    rms.write_text("1.0\nUnknown\nC 200 150 0\n1\nMD UNK lin\n200 150 1500 1500\n"
                   "200 150 1700 1700\n")
    stats = tmp_path / "s.json"
    rc = main(["grid", "render", str(case), "--wells", str(csv), "--wells", str(rms),
               "--size", "160x120", "-o", str(tmp_path / "w.png"), "--stats", str(stats)])
    assert rc == 0 and json.loads(stats.read_text())["wells"] == 3
    capsys.readouterr()
