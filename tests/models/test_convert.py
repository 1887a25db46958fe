"""The models' conversion methods: one registry resolved by name, so the result does not depend
on what was imported before (issue 30: a grid's units came only after ``import geoshade.api``)."""

import json
import subprocess
import sys

import pytest

pytest.importorskip("xarray")

_GRID = ("from geoshade.compute.grid.synthetic import synthetic_grid\n"
         "g = synthetic_grid(3, 2, 2)\n"
         "ds = g.to_xarray()\n"
         "print(json.dumps({'units': {str(v): ds[v].attrs.get('units') for v in ds.data_vars},"
         " 'api': 'geoshade.api' in sys.modules}))")


def _run(code: str) -> dict:
    out = subprocess.run([sys.executable, "-c", "import json, sys\n" + code],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def test_grid_units_do_not_depend_on_import_order():
    alone = _run("import geoshade.models\n" + _GRID)
    after_api = _run("import geoshade.api\n" + _GRID)
    assert not alone["api"] and after_api["api"]
    assert alone["units"] == after_api["units"]
    assert alone["units"]["PERMX"] == "mD" and alone["units"]["SWAT"] == "fraction"


def test_model_method_equals_public_function():
    import geoshade
    from geoshade.compute.grid.synthetic import synthetic_grid

    g = synthetic_grid(3, 2, 2)
    a, b = g.to_xarray(), geoshade.to_xarray(g)
    assert {v: a[v].attrs.get("units") for v in a.data_vars} == \
        {v: b[v].attrs.get("units") for v in b.data_vars}


def test_volume_converts_without_geoshade_io():
    out = _run("import numpy as np\nfrom geoshade.models import VoxelVolume\n"
               "print(json.dumps({'dims': VoxelVolume(np.zeros((1, 2, 3), np.uint8))"
               ".to_xarray().dims}))")
    assert out["dims"] == ["z", "y", "x"]


def test_unknown_converter_is_one_line():
    from geoshade.errors import InputError
    from geoshade.models.convert import convert

    with pytest.raises(InputError, match=r"^int\.to_vtk: no such conversion; expected one of "
                                         r"to_pyvista, to_xarray$"):
        convert("to_vtk", 3)
