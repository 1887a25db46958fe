"""Deck and file wells drawn like restart wells: named pipes in their type's colour (a deck's
WCONPROD/WCONINJE), labels that never overlap (moved or hidden, the picture and the stats say how
many are hidden)."""

from __future__ import annotations

import json
import warnings
from itertools import combinations

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView
from geoshade.grid.geometry import cell_centres_at, world_points
from geoshade.io.grids.deck import read_deck
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.models.wells import DeckWell
from geoshade.styles.annotate import Annotations, annotate
from tests.gl.test_sim_wells import hue, near, project

SIZE = (320, 240)
GREY = "#8c8c8c"
TYPE_HUE = {"producer": "green", "water injector": "blue", "gas injector": "red",
            "unknown": "grey"}

DECK = """RUNSPEC
DIMENS
 8 6 3 /
GRID
INCLUDE
 'g.grdecl' /
SCHEDULE
WELSPECS
 'PROD' 'G' 7 5 1* OIL /
 'WINJ' 'G' 2 2 1* WATER /
 'GINJ' 'G' 7 2 1* GAS /
 'OBS' 'G' 2 5 1* OIL /
/
COMPDAT
 'PROD' 2* 2 3 OPEN /
 'WINJ' 2* 1 3 OPEN /
 'GINJ' 2* 1 1 OPEN /
 'OBS' 2* 3 3 SHUT /
/
WCONPROD
 'PROD' OPEN ORAT 100 /
/
WCONINJE
 'WINJ' WATER OPEN RATE 50 /
 'GINJ' GAS OPEN RATE 50 /
/
END
"""


@pytest.fixture(scope="module")
def deck_grid(tmp_path_factory):
    d = tmp_path_factory.mktemp("deck")
    write_grdecl(synthetic_grid(8, 6, 3), d / "g.grdecl")
    (d / "CASE.DATA").write_text(DECK)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_deck(d / "CASE.DATA")


def _labels_overlapping(boxes) -> int:
    n = 0
    for (ax, ay, aw, ah), (bx, by, bw, bh) in combinations(boxes, 2):
        n += ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah
    return n


def test_deck_wells_are_named_pipes_in_their_type_colour(ctx, deck_grid):
    wells = deck_grid.meta["wells"]
    assert [w.type for w in wells] == ["producer", "water injector", "gas injector", "unknown"]
    v = GridView(deck_grid, size=SIZE, ctx=ctx, exaggeration=5.0, solid_color=GREY,
                 wells=wells, annotations=True)
    try:
        cam = v.camera(view="iso")
        img, st = v.draw(cam)
        heads = {w.name: v.wells.points(w, v.options)[:2] for w in wells}
    finally:
        v.release()
    assert st["wells"] == 4 and st["well_labels"] == 4 and st["well_labels_hidden"] == 0
    labels = st["annotations"]["labels"]
    assert sorted(lab["text"] for lab in labels) == ["GINJ", "OBS", "PROD", "WINJ"]
    assert _labels_overlapping([lab["bbox"] for lab in labels]) == 0
    for w in wells:
        # the pipe above the grid, between its head and the top of its column: its colour
        top = world_points(deck_grid, heads[w.name], 5.0)
        for t in (0.35, 0.65):
            xy = project(cam, (top[0] + t * (top[1] - top[0]))[None], SIZE)[0]
            assert TYPE_HUE[w.type] in {hue(p / 255) for p in near(img, xy, 1).reshape(-1, 3)}, \
                (w.name, t)
    # the first completion cell is on the pipe: the pipe passes through the completions
    assert np.allclose(wells[0].points[1:], cell_centres_at(deck_grid, wells[0].cells))
    assert wells[3].cell_open.tolist() == [False]


def _crowded_field(n=26, seed=4):
    """A 30×20 grid and ``n`` wells whose heads cluster in a few places (labels collide)."""
    g = synthetic_grid(30, 20, 3)
    rng = np.random.default_rng(seed)
    centres = rng.integers(3, 17, (4, 2)) + np.array([[6, 0], [0, 0], [10, 2], [4, 3]])
    wells = []
    for k in range(n):
        i, j = (centres[k % 4] + rng.integers(-2, 3, 2)).clip(0, [29, 19])
        cells = np.array([[i, j, 1], [i, j, 2]])
        pts = cell_centres_at(g, cells)
        wells.append(DeckWell(f"W_{k + 1:02d}", np.vstack([pts[:1] - [0, 0, 300], pts]), pts,
                              cells, type=("producer", "water injector")[k % 2]))
    return g, wells


def test_26_labels_never_overlap_and_the_hidden_ones_are_counted(ctx):
    g, wells = _crowded_field()
    v = GridView(g, size=(640, 480), ctx=ctx, exaggeration=5.0, solid_color=GREY, wells=wells,
                 annotations=True)
    try:
        cam = v.camera(view="iso")
        raw = v.well_labels(cam, (640, 480))   # before placement: at their heads
        _, st = v.draw(cam)
    finally:
        v.release()
    # without placement many labels cover one another (the boxes annotate draws them in)
    _, unplaced = annotate(np.zeros((480, 640, 4), np.uint8), Annotations(labels=tuple(raw)))
    assert len(unplaced["labels"]) == 26
    assert _labels_overlapping([lab["bbox"] for lab in unplaced["labels"]]) >= 20
    labels = st["annotations"]["labels"]
    boxes = [lab["bbox"] for lab in labels]
    assert _labels_overlapping(boxes) == 0
    shown = [lab["text"] for lab in labels]
    assert len(set(shown)) == len(shown) and set(shown) <= {w.name for w in wells}
    hidden = st["well_labels_hidden"]
    assert len(shown) == st["well_labels"] and len(shown) + hidden == 26
    assert st["well_labels_moved"] > 0
    subtitle = [t["text"] for t in st["annotations"]["title"]][-1]
    assert (f"{hidden} overlapping well labels hidden" in subtitle) == (hidden > 0)
    assert hidden > 0   # this crowd cannot all be named
    # every drawn label lies near its own well's head
    heads = {lab.text: (lab.x, lab.y) for lab in raw}
    for lab in labels:
        hx, hy = heads[lab["text"]]
        bx, by, bw, bh = lab["bbox"]
        assert bx - 3 * bh <= hx <= bx + bw + 3 * bh and by - 3 * bh <= hy <= by + 4 * bh


@pytest.mark.gl
def test_cli_rms_file_with_several_wells_named(tmp_path, capsys):
    """One RMS ASCII file with three wells: three grey (unknown type) named pipes."""
    from geoshade.cli.main import main

    case = write_grdecl(synthetic_grid(4, 3, 2), tmp_path / "case.grdecl")
    rms = tmp_path / "three.w"
    rms.write_text("".join(f"1.0\nUnknown\n{n} {x} 150 0\n1\nMD UNK lin\n{x} 150 1400 1400\n"
                           f"{x} 150 1700 1700\n" for n, x in (("A", 60), ("B", 200),
                                                                ("C", 340))))
    stats = tmp_path / "s.json"
    rc = main(["grid", "render", str(case), "--wells", str(rms), "--size", "320x240",
               "-o", str(tmp_path / "w.png"), "--stats", str(stats)])
    st = json.loads(stats.read_text())
    assert rc == 0 and st["wells"] == 3 and st["well_labels_hidden"] == 0
    assert sorted(lab["text"] for lab in st["annotations"]["labels"]) == ["A", "B", "C"]
    capsys.readouterr()


def test_wells_whose_heads_are_out_of_the_picture_are_named_where_they_come_in(ctx):
    """Trajectories starting far above the framed grid: each name sits where its pipe enters the
    picture (inside it, below the top margin), none overlapping."""
    from geoshade.models.wells import Trajectory
    from geoshade.styles.annotate import font_px

    g = synthetic_grid(12, 9, 4)
    b = g.bounds()
    wells = []
    for n in range(6):
        x = b[0, 0] + (0.2 + 0.12 * n) * (b[1, 0] - b[0, 0])
        y = b[0, 1] + 0.5 * (b[1, 1] - b[0, 1])
        k = np.arange(10)
        wells.append(Trajectory(f"WELL-{n}", np.column_stack([x + 3 * k * k, y + 2 * k * k,
                                                              1300 + 60 * k])))
    size = (480, 360)
    v = GridView(g, size=size, ctx=ctx, exaggeration=3.0, solid_color=GREY, wells=wells,
                 annotations=True)
    try:
        cam = v.camera(view="iso")
        heads = project(cam, np.array([world_points(g, w.points[:1], 3.0)[0] for w in wells]),
                        size)
        _, st = v.draw(cam)
    finally:
        v.release()
    assert (heads[:, 1] < 0).all()   # every head is above the picture
    labels = st["annotations"]["labels"]
    assert sorted(lab["text"] for lab in labels) == [f"WELL-{n}" for n in range(6)]
    assert st["well_labels_hidden"] == 0
    assert _labels_overlapping([lab["bbox"] for lab in labels]) == 0
    for lab in labels:
        _, by, _, bh = lab["bbox"]
        assert by >= 0 and by + bh <= size[1] and lab["y"] >= 2 * font_px(size[1]) - 1
