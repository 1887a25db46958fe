"""Colour by an expression (``--property "log10(PERMX)"``): the filter's grammar, giving the
same picture as a property holding those values; report-step names follow the step; bad
expressions are one line before any GL."""

from __future__ import annotations

import json

import numpy as np
import pytest

import geoshade
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.errors import InputError
from geoshade.models import CornerPointGrid

SIZE = (240, 180)


def with_property(g: CornerPointGrid, name: str, values) -> CornerPointGrid:
    """The same grid with one more static property."""
    import dataclasses

    return dataclasses.replace(g, properties={**g.properties, name: np.asfortranarray(values)})


def test_an_expression_draws_what_a_property_of_its_values_draws(ctx):
    g = synthetic_grid(10, 8, 4, faults=True, seed=2)
    # evaluated in the property's own precision (float32: no float64 copy of a 1e8-cell
    # property), so the reference is too
    logk = np.log10(np.asarray(g.properties["PERMX"])).astype(np.float64)
    ref_grid = with_property(g, "LOGK", logk)
    with geoshade.view(g, property="log10( permx )", size=SIZE, ctx=ctx) as v:
        cam = v.camera()
        img, st = v.draw(cam)
        np.testing.assert_allclose(v.values(st["property"], None), logk)
    with geoshade.view(ref_grid, property="LOGK", size=SIZE, ctx=ctx) as ref:
        want, st_ref = ref.draw(cam)
    assert st["property"] == "log10( permx )"
    assert st["color_range"] == pytest.approx(st_ref["color_range"])
    np.testing.assert_array_equal(img, want)


def test_an_expression_of_report_step_properties_follows_the_step(ctx):
    g = synthetic_grid(10, 8, 4, faults=True, seed=2)
    poro = np.asarray(g.properties["PORO"], np.float64)
    with geoshade.view(g, property="PORO * (1 - SWAT)", step=0, size=SIZE, ctx=ctx,
                       annotations=True) as v:
        img0, st0 = v.draw()
        v.update(step=2)
        img2, st2 = v.draw()
        for k in (0, 2):
            swat = np.asarray(g.steps[k]["SWAT"], np.float64)
            np.testing.assert_allclose(v.values("PORO * (1 - SWAT)", k), poro * (1 - swat),
                                       rtol=1e-6)
    assert not np.array_equal(img0, img2)
    # the step is part of the picture's title, as for SWAT itself
    assert st0["annotations"]["title"][1]["text"] != st2["annotations"]["title"][1]["text"]
    assert "PORO * (1 - SWAT)" in st2["annotations"]["title"][0]["text"]


def test_the_colour_bar_of_log10_permeability_says_its_unit(ctx):
    g = synthetic_grid(10, 8, 4, faults=True, seed=2)
    with geoshade.view(g, property="log10(PERMX)", size=(640, 480), ctx=ctx,
                       annotations=True) as v:
        _, st = v.draw()
    bar = st["annotations"]["colorbar"]
    assert bar["label"] == "log10(PERMX) [log10 mD]" and not bar["log"]


def test_undefined_values_get_the_nan_colour(ctx):
    g = synthetic_grid(6, 5, 3, seed=1)
    perm = np.asarray(g.properties["PERMX"], np.float64).copy(order="F")
    perm[0, 0, 0] = -1.0   # log10 of a negative: no value
    g = with_property(g, "PERMX", perm)
    with geoshade.view(g, property="log10(PERMX)", size=SIZE, ctx=ctx) as v:
        _, st = v.draw()
    assert st["no_value_cells"] == 1


@pytest.mark.parametrize(("expr", "msg"), [
    ("PORO > 0.2", r"^property 'PORO > 0.2': a condition, not a number"),
    ("log10(NOSUCH)", r"^property 'log10\(NOSUCH\)': unknown property 'NOSUCH'; available: "),
    ("PORO +", r"^property 'PORO \+': not a valid expression"),
    ("exp(PORO)", r"^property 'exp\(PORO\)': function 'exp' is not allowed"),
    ("2 * 3", r"^property '2 \* 3': names no property"),
    ("__import__('os')", r"^property .*: function '__import__' is not allowed"),
])
def test_bad_expressions_are_one_line_before_any_gl(expr, msg):
    g = synthetic_grid(6, 5, 3, seed=1)
    with pytest.raises(InputError, match=msg):
        geoshade.view(g, property=expr, ctx=object())   # never reaches the context


@pytest.mark.gl
def test_cli_colours_by_an_expression(capsys, tmp_path):
    from geoshade.cli.main import main
    from geoshade.io.grids.grdecl_writer import write_grdecl

    case = tmp_path / "case.grdecl"
    write_grdecl(synthetic_grid(6, 5, 3, seed=1), case)
    out, stats = tmp_path / "k.png", tmp_path / "k.json"
    rc = main(["grid", "render", str(case), "--property", "log10(PERMX)", "--size", "320x240",
               "-o", str(out), "--stats", str(stats)])
    assert rc == 0, capsys.readouterr().err
    s = json.loads(stats.read_text())
    assert s["property"] == "log10(PERMX)" and s["annotations"]["colorbar"]["label"].startswith(
        "log10(PERMX)")
    rc = main(["grid", "render", str(case), "--property", "PORO >", "-o",
               str(tmp_path / "bad.png")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "property 'PORO >'" in err[0]
    assert not (tmp_path / "bad.png").exists()
