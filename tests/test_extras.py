"""A missing extra is one line naming the package and the extra (``pip install 'geoshade[X]'``).

Each test hides the extra's modules (``sys.modules[name] = None`` makes ``import name`` fail as
on a machine without the package) and goes through the CLI where that is practical: exit code 2
and one line on stderr.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from geoshade.cli.main import main
from geoshade.errors import GeoshadeError, MissingExtraError, require

#: extra -> the modules it installs (as imported)
EXTRAS = {
    "netcdf": ("netCDF4", "xarray"),
    "parquet": ("pandas", "pyarrow"),
    "hdf5": ("h5py",),
    "distributed": ("distributed",),
    "video": ("imageio", "imageio_ffmpeg"),
    "colors": ("colorcet",),
    "roff": ("roffio",),
    "geo": ("rasterio",),
    "nrrd": ("nrrd",),
    "threshold": ("scipy",),  # and scikit-image (imported as skimage)
    "web": ("aiohttp",),
}


def hide(monkeypatch, *names: str) -> None:
    """Make ``import name`` (and of its submodules already loaded) fail for each name."""
    for name in names:
        for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
            monkeypatch.setitem(sys.modules, key, None)
        monkeypatch.setitem(sys.modules, name, None)


def one_error_line(capsys, rc: int) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 7, err  # EXIT_EXTRA
    assert len(err) == 1, err
    return err[0]


def test_the_error_is_a_geoshade_error_and_an_import_error(monkeypatch):
    hide(monkeypatch, "h5py")
    with pytest.raises(MissingExtraError) as info:
        require("h5py", "hdf5", "reading HDF5 volumes")
    assert isinstance(info.value, GeoshadeError) and isinstance(info.value, ImportError)
    assert str(info.value) == ("reading HDF5 volumes needs h5py, which is not installed: "
                               "pip install 'geoshade[hdf5]'")
    assert info.value.exit_code == 7  # EXIT_EXTRA


def test_a_broken_dependency_of_the_package_is_named_too(tmp_path, monkeypatch):
    # the package is installed but cannot import one of its own dependencies: say so
    (tmp_path / "geoshade_fake_reader.py").write_text("import geoshade_no_such_dependency\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(MissingExtraError, match=r"^reading netCDF needs geoshade_fake_reader, "
                                                r"which cannot be imported \(.*"
                                                r"geoshade_no_such_dependency.*\): "
                                                r"pip install 'geoshade\[netcdf\]'$"):
        require("geoshade_fake_reader", "netcdf", "reading netCDF")


def test_every_extra_is_declared_with_its_modules():
    import tomllib
    from pathlib import Path

    meta = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())["project"]
    extras = meta["optional-dependencies"]
    core = " ".join(meta["dependencies"]).lower()
    for extra, modules in EXTRAS.items():
        declared = " ".join(extras[extra]).lower()
        for mod in modules:
            assert mod.lower().replace("_", "-") in declared, (extra, mod)
            assert mod.lower().replace("_", "-") not in core, f"{mod} is still a core dependency"
    assert extras["all"] == [f"geoshade[{','.join(EXTRAS)}]"]
    assert "geoshade[all]" in extras["test"] and "geoshade[all]" in extras["bench"]


@pytest.mark.parametrize("hidden", [("netCDF4", "xarray"), ("netCDF4",), ("xarray",)])
def test_geotop_netcdf_without_the_netcdf_extra(tmp_path, monkeypatch, capsys, hidden):
    f = tmp_path / "model.nc"
    f.write_bytes(b"CDF\x01")
    hide(monkeypatch, *hidden)
    line = one_error_line(capsys, main(["info", str(f)]))
    assert line == (f"geoshade: error: reading GeoTOP netCDF needs {hidden[0]}, which is not "
                    "installed: pip install 'geoshade[netcdf]'")


def test_netcdf_fields_without_the_netcdf_extra(tmp_path, monkeypatch):
    from geoshade.io.fields import load_field

    f = tmp_path / "sat.nc"
    f.write_bytes(b"CDF\x01")
    hide(monkeypatch, *EXTRAS["netcdf"])
    msg = r"^reading netCDF fields needs netCDF4, which is not installed: .*'geoshade\[netcdf\]'$"
    with pytest.raises(MissingExtraError, match=msg):
        load_field(f)


def test_hdf5_without_the_hdf5_extra(tmp_path, monkeypatch, capsys):
    f = tmp_path / "vol.h5"
    f.write_bytes(b"\x89HDF\r\n\x1a\n")
    hide(monkeypatch, "h5py")
    line = one_error_line(capsys, main(["info", str(f)]))
    assert line == ("geoshade: error: reading HDF5 dataset needs h5py, which is not installed: "
                    "pip install 'geoshade[hdf5]'")


def test_legends_and_boreholes_without_the_parquet_extra(tmp_path, monkeypatch):
    from geoshade.io.layers.geotop import read_boreholes, read_legend

    f = tmp_path / "logs.parquet"
    f.write_bytes(b"PAR1")
    hide(monkeypatch, *EXTRAS["parquet"])
    with pytest.raises(MissingExtraError, match=r"^reading GeoTOP legends needs pandas, .*"
                                                r"pip install 'geoshade\[parquet\]'$"):
        read_legend("lithok", tmp_path)
    with pytest.raises(MissingExtraError, match=r"^reading borehole logs needs pandas, .*"
                                                r"pip install 'geoshade\[parquet\]'$"):
        read_boreholes(f)


def test_scheduler_address_without_the_distributed_extra(tmp_path, monkeypatch, capsys):
    f = tmp_path / "vol.npy"
    np.save(f, np.zeros((4, 4, 4), np.uint8))
    hide(monkeypatch, "distributed")
    rc = main(["core", "porosity", str(f), "--select", "0", "0", "-o", str(tmp_path / "p.png"),
               "--scheduler", "tcp://127.0.0.1:9"])
    line = one_error_line(capsys, rc)
    assert line.startswith("geoshade: error: a dask cluster")
    assert line.endswith(" needs distributed, which is not installed: "
                         "pip install 'geoshade[distributed]'")


def test_mp4_without_the_video_extra(tmp_path, monkeypatch):
    from geoshade.render.video import VideoWriter

    hide(monkeypatch, *EXTRAS["video"])
    with pytest.raises(MissingExtraError, match=r"^writing MP4 video needs imageio_ffmpeg, .*"
                                                r"pip install 'geoshade\[video\]'$"):
        with VideoWriter(tmp_path / "a.mp4") as w:
            w.append(np.zeros((4, 4, 4), np.uint8))
    assert not (tmp_path / "a.mp4").exists()


HIDE_ALL = ("import sys\n"
            f"for _m in {sorted(m for mods in EXTRAS.values() for m in mods)!r}:\n"
            "    sys.modules[_m] = None\n")


def run_lean(code: str, cwd) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter where no extra is installed."""
    return subprocess.run([sys.executable, "-c", HIDE_ALL + code], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_every_module_imports_without_the_extras(tmp_path):
    # the viewer is the `viewer` extra (PySide6), not a reader: it is left out here
    proc = run_lean(
        "import importlib, pkgutil, geoshade\n"
        "names = [m.name for m in pkgutil.walk_packages(geoshade.__path__, 'geoshade.')\n"
        "         if not m.name.startswith('geoshade.viewer')]\n"
        "for n in names:\n"
        "    importlib.import_module(n)\n"
        "print(len(names))\n", tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert int(proc.stdout.split()[-1]) > 50


@pytest.mark.gl
def test_demo_runs_on_the_core_install(tmp_path):
    proc = run_lean("from geoshade.cli.main import main\nsys.exit(main(['demo']))\n", tmp_path)
    if proc.returncode == 3:
        pytest.skip(proc.stderr.strip().splitlines()[-1])
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert (tmp_path / "geoshade-demo" / "stats.json").is_file()


def test_a_colorcet_map_without_colorcet_names_the_extra(monkeypatch):
    from geoshade.errors import InputError
    from geoshade.styles.palette import colormap

    hide(monkeypatch, "colorcet")
    with pytest.raises(InputError, match=r"unknown colour map 'fire'.*geoshade\[colors\]"):
        colormap("fire")
    assert colormap("viridis").name == "viridis"   # matplotlib's own need nothing


def test_roff_without_the_roff_extra(tmp_path, monkeypatch, capsys):
    f = tmp_path / "grid.roff"
    f.write_bytes(b"roff-bin\0")
    hide(monkeypatch, *EXTRAS["roff"])
    line = one_error_line(capsys, main(["info", str(f)]))
    assert line == ("geoshade: error: reading ROFF grid (RMS) needs roffio, which is not "
                    "installed: pip install 'geoshade[roff]'")
