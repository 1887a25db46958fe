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
