"""A progressive GridView (issue 26, target 2): the coarse level of detail first (a grid store's
stored level, or merged in memory), then the full picture, pixel for pixel the non-progressive
View's."""

from __future__ import annotations

import numpy as np
import pytest

from geoshade.compute.grid.coarse import coarse_grid
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.grid import GridView
from geoshade.grid import lod as lod_mod
from geoshade.grid.lod import write_coarse_level
from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

SIZE = (320, 240)
OPTS = {"property": "PORO", "exaggeration": 5.0, "size": SIZE}


@pytest.fixture
def small_budget(monkeypatch):
    monkeypatch.setattr(lod_mod, "PREVIEW_CELLS", 2000)


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(24, 16, 8, seed=3)


def test_coarse_then_exactly_the_full_picture(ctx, grid, small_budget):
    opts = {**OPTS, "size": (560, 420)}   # room for the note's whole line
    with GridView(grid, ctx=ctx, progressive=True, annotations=True, **opts) as view:
        assert view.loading and view.drawing is None
        (coarse, cs), (full, fs) = view.pictures(frames=1)
        assert not view.loading
    with GridView(grid, ctx=ctx, annotations=True, **opts) as ref_view:
        ref, rs = ref_view.draw(frames=1)
    assert np.array_equal(full, ref)                     # pixel for pixel
    assert cs["coarse"] is True and cs["coarse_ratio"] == 2 and "coarse" not in fs
    assert cs["cells"] == coarse_grid(grid, 2).ncells and fs["cells"] == grid.ncells
    assert cs["color_range"] == rs["color_range"]        # the full grid's colour range
    note = "coarse preview, cells 2×2×2 (1/2 resolution) — full picture loading"
    assert note in str(cs["annotations"]["title"]) and note not in str(fs["annotations"])
    assert not np.array_equal(coarse, ref)


def bbox(img):
    rows, cols = np.nonzero((img[..., :3] != 255).any(-1))
    return np.array([rows.min(), rows.max(), cols.min(), cols.max()])


def test_the_preview_has_the_full_pictures_framing(ctx, grid, small_budget):
    with GridView(grid, ctx=ctx, progressive=True, **OPTS) as view:
        coarse, _ = view.draw(frames=1)
    with GridView(grid, ctx=ctx, **OPTS) as ref_view:
        ref, _ = ref_view.draw(frames=1)
    # the outline is the same grid's (its kept pillars): a pixel or two apart at most
    assert np.abs(bbox(coarse) - bbox(ref)).max() <= 2


def test_a_change_while_loading_supersedes(ctx, grid, small_budget):
    with GridView(grid, ctx=ctx, progressive=True, **OPTS) as view:
        first = view.preview.view
        assert view.jobs(view="top") == []
        jobs = view.jobs(slice="k=2:6", property="PERMX")
        assert [j.key for j in jobs] == [view.refine_key()] and first.released
        assert view.preview.view.options.slice == (slice(0, 12), slice(0, 8), slice(1, 3))
        jobs[0].run()
        img, st = view.draw(frames=1)
    with GridView(grid, ctx=ctx, slice="k=2:6", **{**OPTS, "property": "PERMX"},
                  view="top") as ref_view:
        ref, _ = ref_view.draw(frames=1)
    assert np.array_equal(img, ref) and "coarse" not in st


def test_store_preview_from_its_stored_level(ctx, tmp_path):
    g = synthetic_grid(16, 12, 8, seed=5)
    store = tmp_path / "g.zarr"
    write_grid_store(ModelSource(g), store, chunks=(8, 6, 4), input_label="g")
    lazy = open_grid_store(store)
    with pytest.warns(UserWarning, match="no coarse level in the store"), \
            GridView(lazy, ctx=ctx, progressive=True, **OPTS) as view:
        assert not view.loading
        view.draw(frames=1)
    write_coarse_level(store, 4)
    with GridView(open_grid_store(store), ctx=ctx, progressive=True, **OPTS) as view:
        assert view.loading and view.preview.ratio == 4
        (_, cs), (full, _) = view.pictures(frames=1)
    with GridView(open_grid_store(store), ctx=ctx, **OPTS) as ref_view:
        ref, _ = ref_view.draw(frames=1)
    assert cs["cells"] == 4 * 3 * 2 and np.array_equal(full, ref)


def test_small_grid_draws_at_once(ctx, grid):
    with GridView(grid, ctx=ctx, progressive=True, **OPTS) as view:
        assert not view.loading and len(list(view.pictures(frames=1))) == 1


@pytest.mark.gl   # draws through the CLI (no ctx fixture to mark it)
def test_cli_progressive_writes_the_coarse_picture(tmp_path, capsys):
    import json

    from geoshade.cli.main import main
    from geoshade.io.grids.grdecl_writer import write_grdecl

    write_grdecl(synthetic_grid(24, 16, 8, seed=3), tmp_path / "g.grdecl")
    store, out = tmp_path / "g.zarr", tmp_path / "g.png"
    assert main(["grid", "ingest", str(tmp_path / "g.grdecl"), "-o", str(store),
                 "--chunks", "12", "8", "4", "--coarse", "2"]) == 0
    assert main(["grid", "render", str(store), "--property", "PORO", "-o", str(out),
                 "--size", "320x240", "--stats", str(tmp_path / "s.json")]) == 0
    assert not (tmp_path / "g.coarse.png").exists()     # only when asked
    plain = out.read_bytes()
    assert main(["grid", "render", str(store), "--property", "PORO", "-o", str(out),
                 "--size", "320x240", "--progressive", "--stats",
                 str(tmp_path / "s.json")]) == 0
    text = capsys.readouterr().out
    assert "g.coarse.png: coarse preview, cells 2×2×2 (1/2 resolution) after" in text
    assert (tmp_path / "g.coarse.png").read_bytes() != plain
    assert out.read_bytes() == plain                     # the full picture, as without
    st = json.loads((tmp_path / "s.json").read_text())["progressive"]
    assert st["coarse_ratio"] == 2 and st["coarse_s"] <= st["full_s"]
    assert main(["grid", "ingest", str(store), "--coarse", "auto"]) == 0   # an existing store
    assert "g.zarr/lod: coarse level, cells merged 2×2×2: 12×8×4 cells" in \
        capsys.readouterr().out


def test_a_pick_on_the_preview_names_the_cells_it_merges(ctx, grid, small_budget):
    """While loading, a pick says which full-resolution cells the coarse one merges (1-based
    ranges; the index: the first of them) and that its value is merged; the full picture's
    pick at the same pixel is one of those cells."""
    with GridView(grid, ctx=ctx, progressive=True, **OPTS) as view:
        view.draw(frames=1)
        hits = 0
        for x, y in [(160, 120), (130, 110), (190, 130), (150, 140)]:
            raw = view.preview.view.pick(x, y)      # the coarse grid's own cell
            hit = view.pick(x, y)
            if raw is None:
                assert hit is None
                continue
            lo = tuple(2 * c for c in raw.index)
            hi = tuple(min(2 * c + 2, n) - 1 for c, n in zip(raw.index, grid.dims, strict=True))
            assert hit.index == lo
            assert hit.label == hit.ijk_label == " ".join(
                f"{a}={l + 1}" if h == l else f"{a}={l + 1}–{h + 1}"
                for a, l, h in zip("IJK", lo, hi, strict=True))
            assert hit.extra[-1] == ("preview", "the merged value of 2×2×2 cells (exact in "
                                                "the full picture)")
            view.refine()
            view.draw(frames=1)
            full = view.pick(x, y)
            assert full is not None and not any(k == "preview" for k, _ in full.extra)
            assert all(a <= v <= b for a, v, b in zip(lo, full.index, hi, strict=True)), \
                (lo, full.index, hi)
            hits += 1
            break
        assert hits


def test_the_note_says_when_faults_inside_merged_cells_are_smoothed(ctx, grid, monkeypatch):
    """At 2×2×2 both faults of the grid lie on block boundaries (kept exactly); at 4×4×4 one
    lies inside blocks, and the preview's note says its throw is smoothed."""
    from geoshade.compute.grid.coarse import faults_inside_blocks

    said = {}
    for budget, f in ((2000, 2), (100, 4)):
        monkeypatch.setattr(lod_mod, "PREVIEW_CELLS", budget)
        with GridView(grid, ctx=ctx, progressive=True, **OPTS) as view:
            assert view.preview.ratio == f
            said[f] = "faults inside merged cells smoothed" in view.preview.note
        assert said[f] == (faults_inside_blocks(grid.faults, grid.dims, f) > 0)
    assert said == {2: False, 4: True}
