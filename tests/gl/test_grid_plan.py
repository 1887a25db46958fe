"""GPU plans before allocation (issue 16, target 3): each approach's planned bytes equal what its
View then allocates; a plan over ``gpu_memory`` is refused before any GPU object."""

import json

import numpy as np
import pytest

from geoshade.compute.grid.faces import visible_faces
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.grid import GridView
from geoshade.grid.plan import VARIANTS, cells_with_faces, gpu_plans, parse_bytes


@pytest.fixture(scope="module")
def grid():
    return synthetic_grid(16, 12, 5, seed=7, steps=0)


def test_every_planned_approach_allocates_exactly_its_plan(ctx, grid):
    plans = gpu_plans(grid)
    assert plans["cells_drawn"] == len(np.unique(visible_faces(grid).cell_index()))
    for row, (approach, bits, store) in zip(plans["rows"], VARIANTS, strict=True):
        with GridView(grid, property="PORO", approach=approach, zcorn_bits=bits,
                      zcorn_store=store, size=(64, 48), ctx=ctx, annotations=False) as v:
            _, st = v.draw(frames=1)
            assert st["gpu_bytes"] == row["bytes"] == st["gpu_plan_bytes"], row
            assert v.visual.cache.breakdown() == row["plan"]


def test_a_plan_over_gpu_memory_is_refused_before_any_gpu_object(ctx, grid, monkeypatch):
    from geoshade.render.visuals.grid import visual

    made = []
    monkeypatch.setattr(visual.GridVisual, "__init__",
                        lambda *a, **k: made.append(1) or (_ for _ in ()).throw(AssertionError))
    with pytest.raises(InputError, match=r"approach 3 \(faces\) needs .* GPU memory, more than"):
        GridView(grid, property="PORO", gpu_memory="1K", size=(64, 48), ctx=ctx)
    assert not made


def test_cells_with_faces_counts_distinct_cells():
    cells = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [2, 3, 1]], np.int32)
    assert cells_with_faces(cells, (3, 4, 2)) == 3


@pytest.mark.parametrize("bad", ["", "lots", "-1G", "0", "1X"])
def test_bad_sizes_are_one_line(bad):
    with pytest.raises(InputError, match="gpu_memory"):
        parse_bytes(bad)


def test_info_gpu_prints_every_approach(tmp_path, capsys, grid):
    from geoshade.cli.main import main
    from geoshade.io.grids.grdecl_writer import write_grdecl

    path = tmp_path / "g.grdecl"
    write_grdecl(grid, path)
    plans = gpu_plans(grid)
    mid = sorted(r["bytes"] for r in plans["rows"])[3]  # some approaches fit, some do not
    assert main(["info", str(path), "--gpu", "--gpu-memory", str(mid), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)["gpu_plan"]
    assert d["gpu_memory"] == mid and len(d["rows"]) == len(VARIANTS)
    assert [r["fits"] for r in d["rows"]] == [r["bytes"] <= mid for r in plans["rows"]]
    assert {r["fits"] for r in d["rows"]} == {True, False}
    assert main(["info", str(path), "--gpu", "--gpu-memory", str(mid)]) == 0
    out = capsys.readouterr().out
    assert "GPU plan:" in out and "3 faces" in out and "NO" in out
