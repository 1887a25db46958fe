"""What importing geoshade loads (issue 30): ``import geoshade`` and ``import geoshade.io``
import no reader package, and ``geoshade.load`` of a ``.npy`` imports only what a ``.npy``
needs; the readers are imported by name from the format table (:mod:`geoshade.io.formats`) when
a file of their kind is read. Each case runs in a fresh interpreter."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

#: packages that read other formats (or draw): never loaded before a file of their kind is read
READERS = ("resfo", "tifffile", "zarr", "roffio", "netCDF4", "h5py", "rasterio", "nrrd",
           "xarray", "pandas", "pyarrow", "skimage", "scipy", "numba", "pyvista", "dask",
           "moderngl", "matplotlib")


def loaded(code: str) -> set[str]:
    """The top-level packages loaded after running ``code`` in a fresh interpreter."""
    prog = (code + "\nimport sys, json\n"
            "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})))")
    out = subprocess.run([sys.executable, "-c", prog], capture_output=True, text=True,
                         check=True).stdout
    return set(json.loads(out.strip().splitlines()[-1]))


@pytest.mark.parametrize("code", ["import geoshade", "import geoshade.io",
                                  "import geoshade.io.formats"])
def test_importing_loads_no_reader(code):
    assert not loaded(code) & set(READERS)


def test_loading_a_npy_loads_no_other_reader(tmp_path):
    import numpy as np

    np.save(tmp_path / "v.npy", np.zeros((2, 3, 4), np.uint8))
    got = loaded(f"import geoshade\nv = geoshade.load({str(tmp_path / 'v.npy')!r})\n"
                 "assert v.shape_xyz == (4, 3, 2)")
    assert not got & set(READERS), sorted(got & set(READERS))


def test_reading_a_kind_imports_its_reader(tmp_path):
    import numpy as np
    import tifffile

    tifffile.imwrite(tmp_path / "v.tif", np.zeros((7, 5, 6), np.uint8))
    got = loaded(f"import geoshade.io\ngeoshade.io.load({str(tmp_path / 'v.tif')!r})")
    assert "tifffile" in got and not got & {"resfo", "zarr", "rasterio", "h5py"}


def test_the_table_names_importable_readers():
    code = ("from geoshade.io.formats import FORMATS, resolve\n"
            "print(json.dumps([f.name for f in FORMATS if not callable(resolve(f.reader))]))")
    out = subprocess.run([sys.executable, "-c", "import json\n" + code], capture_output=True,
                         text=True, check=True).stdout
    assert json.loads(out) == []


def test_a_grid_store_is_read_and_framed_without_distributed(tmp_path):
    """dask looks for a cluster's client by importing ``distributed`` (0.4 s) at every compute
    with a scheduler's name or none; a store's open, its index check, its framing bounds and
    its faces are computed with dask's own functions (:func:`geoshade.scheduler.dask_get`),
    so the cluster package is not loaded where no cluster is used."""
    pytest.importorskip("distributed")
    from geoshade.compute.grid.index_faces import store_index
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.stores.grid_store import ModelSource, write_grid_store

    grid = synthetic_grid(9, 7, 4, inactive_fraction=0.2, steps=1, seed=3)
    store = tmp_path / "g.zarr"
    write_grid_store(ModelSource(grid), store, (5, 4, 3), index=store_index)
    code = (f"import geoshade\ng = geoshade.load({str(store)!r})\n"
            "from geoshade.grid.geometry import display_bounds\n"
            "from geoshade.grid.lazy import store_index_of\n"
            "from geoshade.compute.grid.chunks import visible_faces_chunked\n"
            "from geoshade.io.stores.grid_index import GridIndex\n"
            "assert isinstance(store_index_of(g), GridIndex)\n"
            "display_bounds(g)\n"
            "assert len(visible_faces_chunked(g, None).cells) > 0\n")
    got = loaded(code)
    assert "dask" in got and "distributed" not in got
