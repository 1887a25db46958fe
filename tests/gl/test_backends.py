"""A grid View uses a source (memory, indexed store, chunked store) and a drawing (here; the
cluster's in tests/distributed/test_backends_cluster.py), each behind one interface
(GridSource, FacesDrawing); the core View a source (array, store) and a drawing (whole,
bricked; cluster) behind two more (VolumeSource, BricksDrawing): the same calls drive each to
the same pictures, and none holds the View."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.compute.voxels.synthetic import synthetic_core
from geoshade.core import CoreView
from geoshade.core.backends import BricksDrawing
from geoshade.core.sources import VolumeSource
from geoshade.grid import GridView
from geoshade.grid.backends import Applied, FacesDrawing, GridSource
from geoshade.grid.colours import ColourPlan

SIZE = (120, 90)
FACE_STEPS = ({"filter": "PORO > 0.2"}, {"slice": "k=1:5", "faults": "highlight"},
              {"filter": None, "slice": None, "faults": "show"})
SELECTS = ((0, 9000), (3000, 20000))


def holds_no_view(obj) -> None:
    """A drawing or source keeps no reference to a View (it is given what it needs)."""
    from geoshade.render.view import View

    assert not any(isinstance(v, View) for v in vars(obj).values()), type(obj).__name__


def drive_faces(view) -> list[np.ndarray]:
    """Drive a grid View's drawing through the :class:`FacesDrawing` calls (prepare, apply,
    colours, drawing changes, draw, stats, GPU bytes, release); the pictures on the way."""
    d, src = view.drawing, view.source
    assert isinstance(d, FacesDrawing) and isinstance(src, GridSource)
    holds_no_view(d)
    holds_no_view(src)
    pictures = [view.draw("iso", frames=1, count=False)[0]]
    for changes in FACE_STEPS:
        before = view.options
        prepared = d.prepare(view.options.replace(view.grid, **changes))   # CPU half
        assert view.options is before   # the drawing returns what it prepared
        out = d.apply(prepared, view.colours.current)                     # GL half
        assert isinstance(out, Applied) and out.changes == prepared.changes
        assert view.options is before   # ... and what it applied: the View makes it current
        view.apply_faces(d.prepare(view.options.replace(view.grid, **changes)))
        for k in ("filter", "slice", "faults"):   # the prepared options are current
            assert getattr(view.options, k) == prepared.changes[k], k
        pictures.append(view.draw("iso", frames=1, count=False)[0])
    d.colours(view.options, ColourPlan(None, None, None, view.palette))   # one uniform colour
    pictures.append(view.draw("top", frames=1, count=False)[0])
    view.update(property="PERMX", edges="quad")   # colours and drawing_changed through update
    img, st = view.draw("iso", frames=1, count=False)
    pictures.append(img)
    for key in ("faces", "approach", "zcorn_store", "zcorn_bits", "zcorn_max_error",
                "gpu_plan_bytes", "gpu_breakdown", "edges"):
        assert key in st, key
    assert st["edges"] == "quad" and st["faces"] > 0 and st["method"] == d.method()
    assert d.gpu_bytes > 0 and st["gpu_bytes"] >= d.gpu_bytes
    d.release()
    d.release()   # idempotent
    assert d.gpu_bytes == 0
    return pictures


def drive_bricks(view) -> list[np.ndarray]:
    """Drive a core View's drawing through the :class:`BricksDrawing` calls (prepare, apply,
    colours, remake, draw, stats, GPU bytes, release); the pictures on the way."""
    d, src = view.drawing, view.source
    assert isinstance(d, BricksDrawing) and isinstance(src, VolumeSource)
    holds_no_view(d)
    holds_no_view(src)
    pictures = [view.draw("iso", frames=1, count=False)[0]]
    for select in SELECTS:
        before = view.maps
        o = view.options.replace(view.volume, select=select)
        d.prepare(o)   # maps built up front (whole) or None (bricks build theirs)
        assert view.maps is before   # the drawing returns what it made
        view.update(select=select)   # apply, through the View
        assert view.drawing is d and view.maps.count > 0 and view.maps is not before
        pictures.append(view.draw("iso", frames=1, count=False)[0])
    view.update(colormap="magma")   # colours
    pictures.append(view.draw("iso", frames=1, count=False)[0])
    view.update(method="gs")        # remake
    img, st = view.draw("iso", frames=1, count=False)
    pictures.append(img)
    assert st["voxels_selected"] == view.maps.count and d.gpu_bytes > 0
    assert d.notes() == []
    d.release()
    d.release()
    assert d.gpu_bytes == 0
    return pictures


@pytest.fixture(scope="module")
def grids(tmp_path_factory):
    """One grid in memory, as a grid store with its index and as one without."""
    from geoshade.compute.grid.index_faces import store_index
    from geoshade.io.stores.grid_store import ModelSource, open_grid_store, write_grid_store

    grid = synthetic_grid(16, 12, 6, seed=4, steps=2)
    d = tmp_path_factory.mktemp("backends")
    write_grid_store(ModelSource(grid), d / "g.zarr", chunks=(8, 8, 3))
    write_grid_store(ModelSource(grid), d / "i.zarr", chunks=(8, 8, 3), index=store_index)
    return grid, open_grid_store(d / "i.zarr"), open_grid_store(d / "g.zarr")


def test_every_source_draws_the_same_pictures_here(ctx, grids):
    """The same drawing (here) of the three sources: the same pictures, step by step."""
    runs = []
    for grid, source in zip(grids, ("memory", "indexed store", "chunked store"), strict=True):
        with GridView(grid, ctx=ctx, size=SIZE, property="PORO", annotations=False) as v:
            assert v.source.name == source and v.drawing.name == "here"
            assert v.visual is v.drawing.visual
            runs.append(drive_faces(v))
    ref = runs[0]
    assert len(ref) == 6 and len({x.tobytes() for x in ref}) >= 5   # the steps changed it
    for got in runs[1:]:
        for i, (x, y) in enumerate(zip(ref, got, strict=True)):
            np.testing.assert_array_equal(x, y, err_msg=f"picture {i}")


def test_the_bricks_drawings_of_both_sources_draw_the_same_pictures(ctx):
    """Whole and bricked, of an array and of a store (dask): the same pictures."""
    from geoshade.compute.voxels.lazy import as_dask

    vol = synthetic_core(64, porosity=0.3, seed=5)
    store = dataclasses.replace(vol, data=as_dask(vol.data, chunks=(32, 32, 32)))
    runs = []
    for v, source in ((vol, "array"), (store, "store")):
        for bricks, drawing in ((None, "whole"), (32, "bricked")):
            with CoreView(v, ctx=ctx, size=SIZE, select=(0, 15000), method="raycast",
                          bricks=bricks, annotations=False) as view:
                assert (view.source.name, view.drawing.name) == (source, drawing)
                assert view.visual is view.drawing.visual
                runs.append(drive_bricks(view))
    ref = runs[0]
    assert len({x.tobytes() for x in ref}) >= 3
    for got in runs[1:]:
        for i, (x, y) in enumerate(zip(ref, got, strict=True)):
            np.testing.assert_array_equal(x, y, err_msg=f"picture {i}")


def test_a_new_box_may_change_the_drawing(ctx):
    """Whole or bricked is decided per box: a box within one brick side is drawn whole."""
    vol = synthetic_core(64, seed=5)
    with CoreView(vol, ctx=ctx, size=SIZE, select=(0, 15000), bricks=32) as v:
        first = v.drawing
        assert first.name == "bricked"
        v.update(box=[0, 0, 0, 32, 32, 32])
        assert v.drawing.name == "whole" and first.gpu_bytes == 0   # the old one released
        v.draw(frames=1)


def test_only_render_distributed_calls_private_renderer_methods():
    """No module outside render/distributed calls a ``_``-prefixed method or attribute of a
    distributed renderer (a View's backend releases its scene with ``release_scene``)."""
    import ast
    from pathlib import Path

    import geoshade

    root = Path(geoshade.__file__).parent
    bad = []
    for path in sorted(root.rglob("*.py")):
        if path.parent == root / "render" / "distributed":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                    and not node.attr.startswith("__")):
                continue
            owner = node.value
            name = owner.attr if isinstance(owner, ast.Attribute) else getattr(owner, "id", "")
            if "renderer" in name.lower() or node.attr == "_call_all":
                bad.append(f"{path.relative_to(root)}:{node.lineno} .{node.attr}")
    assert not bad, bad


def test_what_a_store_does_not_draw_leaves_the_view_as_it_was(ctx, grids, monkeypatch):
    """Refused by the options before any GL (open) or any GPU object (update)."""
    import geoshade.render.context as context
    from geoshade.errors import InputError

    _, _, store = grids
    with GridView(store, ctx=ctx, size=SIZE, property="PORO") as v:
        visual = v.visual
        with pytest.raises(InputError, match="approach 3"):
            v.update(approach=2)
        assert v.options.approach == 3 and v.visual is visual

    def no_gl(*a, **k):
        raise AssertionError("a GL context was made")

    monkeypatch.setattr(context, "get_context", no_gl)
    with pytest.raises(InputError, match="cutting plane"):
        GridView(store, size=SIZE, property="PORO", plane="1,0,0")
