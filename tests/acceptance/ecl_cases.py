"""ECLIPSE output variants made at test time: local grid refinements, hourly non-unified
restarts, dual porosity/permeability, the old GRID file, ECLIPSE's inactive zero corners and
undefined values.

Run ``python -m tests.acceptance.ecl_cases`` to make them all ahead of the tests. Everything goes
into :data:`~tests.acceptance.make_cases.CACHE` (git-ignored); nothing here is committed but
the code. Each case says where its data come from and what its oracle is:

- :func:`spe1_lgr`: OPM Flow 2026.4 runs the committed SPE1 deck with two ``CARFIN`` local grid
  refinements (LGR1 4×4×1 in I=2..3 J=2..3 K=1, LGR2 4×4×4 in I=7..8 J=7..8 K=2..3) and six
  monthly steps: its own EGRID/INIT/UNRST LGR sections. Oracle: resfo's arrays.
- :func:`spe1_hourly`: OPM Flow runs SPE1 with 24 hourly steps then two daily ones, written as
  non-unified files (``.X0000`` …): INTEHEAD keeps each step's hour. Oracle: resfo's INTEHEAD.
- :func:`spe1_dual`: the SPE1 run rewritten with resfo as ECLIPSE lays out a ``DUALPORO`` (or
  ``DUALPERM``) case (FILEHEAD item 6, ACTNUM 0..3, LOGIHEAD item 15, INIT and restart arrays
  of the matrix's then the fracture's active cells; resdata's ``rd_grid.cpp``): OPM Flow does
  not simulate dual porosity. Oracle: the arrays written.
- :func:`reek_grid_file`: the real Reek EGRID (ECLIPSE output, shared data) written as an old
  binary GRID file, each cell's corners from xtgeo. Oracle: xtgeo's corners.
- :func:`spe1_eclipse_style`: the SPE1 run with 10 cells made inactive as ECLIPSE 2018 writes
  them (ACTNUM 0, their ZCORN 0) and an INIT array with ECLIPSE's undefined value -1e20.
  Oracle: the arrays written, numpy.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import resfo

from tests.acceptance.make_cases import (
    CACHE,
    REAL,
    SHARED,
    CaseUnavailableError,
    made_once,
    spe1_field,
)

#: the two refinements of :func:`spe1_lgr`: name, I1 I2 J1 J2 K1 K2 (1-based), NX NY NZ
LGRS = (("LGR1", (2, 3, 2, 3, 1, 1), (4, 4, 1)), ("LGR2", (7, 8, 7, 8, 2, 3), (4, 4, 4)))

_RUN_FLOW = """
import sys
from opm.simulators import BlackOilSimulator
sim = BlackOilSimulator(sys.argv[1], args=sys.argv[2:])
sim.step_init()
while not sim.check_simulation_finished():
    sim.step()
sim.step_cleanup()
"""


def _deck(schedule: str, unified: bool = True, grid_extra: str = "") -> str:
    """The committed SPE1 deck with its TSTEPs replaced by ``schedule`` (and ``grid_extra`` at
    the end of its GRID section; UNIFOUT dropped for non-unified output)."""
    src = (REAL / "opm_spe1_field" / "SPE1CASE1.DATA").read_text()
    if not unified:
        src = src.replace("UNIFIN\nUNIFOUT", "UNIFIN")
    if grid_extra:
        src = src.replace("ECHO\n\nPROPS", grid_extra + "ECHO\n\nPROPS")
    return src[:src.index("TSTEP\n")] + schedule + "\nEND\n"


def _flow(folder: Path, name: str, deck: str, want: str) -> Path:
    """Run OPM Flow on ``deck`` in ``folder`` (``--parsing-strictness=low``: CARFIN is parsed);
    the EGRID, once ``want`` exists."""
    egrid = folder / f"{name}.EGRID"
    if egrid.is_file() and (folder / want).is_file():
        return egrid
    try:
        import opm.simulators  # noqa: F401
    except ImportError as err:
        raise CaseUnavailableError(f"OPM Flow is not installed (pip install opm==2026.4 "
                                   f"opm-simulators==2026.4, the test extra): {err}") from None
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    (folder / f"{name}.DATA").write_text(deck)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    try:
        run = subprocess.run([sys.executable, "-c", _RUN_FLOW, f"{name}.DATA",
                              "--parsing-strictness=low"], cwd=folder, env=env,
                             capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        raise CaseUnavailableError(f"OPM Flow did not finish {name} in 300 s") from None
    if run.returncode != 0 or not (folder / want).is_file():
        tail = (run.stderr or run.stdout).strip().splitlines()[-1:] or ["no output"]
        raise CaseUnavailableError(f"OPM Flow did not run {name}.DATA: {tail[0]}")
    return egrid


@made_once
def spe1_lgr(cache: Path = CACHE) -> Path:
    """SPE1 with two CARFIN refinements, six monthly steps, run by OPM Flow: its EGRID."""
    carfin = "".join(f"CARFIN\n'{n}' {' '.join(map(str, box))} {' '.join(map(str, size))} /\n"
                     "ENDFIN\n" for n, box, size in LGRS)
    deck = _deck("TSTEP\n31 28 31 30 31 30 /\n", grid_extra=carfin)
    return _flow(cache / "spe1_lgr", "LGRCASE", deck, "LGRCASE.UNRST")


@made_once
def spe1_hourly(cache: Path = CACHE) -> Path:
    """SPE1 with 24 hourly steps and two daily ones, non-unified restarts: its EGRID."""
    deck = _deck("TSTEP\n24*0.041666666666666664 /\n\nTSTEP\n2*1 /\n", unified=False)
    return _flow(cache / "spe1_hourly", "HOURLY", deck, "HOURLY.X0026")


def _kw(name: str) -> str:
    return f"{name:<8}"


@made_once
def spe1_dual(cache: Path = CACHE, kind: int = 1) -> Path:
    """The SPE1 run as a dual-porosity (``kind`` 1) or dual-permeability (2) case in ECLIPSE's
    layout: its EGRID.

    Matrix: SPE1's cells, all active, with SPE1's values. Fracture: active where ``(i + j) % 3``
    is not 0 (ACTNUM 3, else 1), PORO 0.01, PERMX ten times the matrix's, restart values the
    matrix's of the step times 0.5 (SWAT, SGAS) or minus 10 (PRESSURE, RS the same).
    """
    name = "DUALPORO" if kind == 1 else "DUALPERM"
    folder = cache / f"spe1_{name.lower()}"
    egrid = folder / f"{name}.EGRID"
    if egrid.is_file() and (folder / f"{name}.UNRST").is_file():
        return egrid
    src = spe1_field(cache)
    folder.mkdir(parents=True, exist_ok=True)
    nx, ny, nz = 10, 10, 3
    i, j, _ = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    frac = ((i + j) % 3 != 0).reshape(-1, order="F")
    grid = []
    for k, v in _read(src):
        if k.strip() == "FILEHEAD":
            v = np.array(v, np.int32)
            v[5] = kind
        elif k.strip() == "ACTNUM":
            v = np.where(frac, 3, 1).astype(np.int32)
        grid.append((k, v))
    _write(egrid, grid)
    init = []
    for k, v in _read(src.with_suffix(".INIT")):
        name_ = k.strip()
        if name_ == "INTEHEAD":
            v = np.array(v, np.int32)
            v[10], v[11] = 2 * nz, nx * ny * nz + int(frac.sum())  # the deck's NZ, both media
        elif name_ == "LOGIHEAD":
            v = np.array(v, bool)
            v[14] = True
        elif name_ == "PORV":  # every cell of both media (2·ncells), 0 where inactive
            v = np.concatenate([v, np.where(frac, v * 0.1, 0).astype(v.dtype)])
        elif getattr(v, "size", 0) == nx * ny * nz and v.dtype.kind in "fi":
            f = {"PORO": np.full(frac.sum(), 0.01, v.dtype),
                 "PERMX": (v[frac] * 10).astype(v.dtype)}.get(name_, v[frac])
            v = np.concatenate([v, f])
        init.append((k, v))
    _write(egrid.with_suffix(".INIT"), init)
    rst = []
    for k, v in _read(src.with_suffix(".UNRST")):
        name_ = k.strip()
        if name_ == "INTEHEAD":
            v = np.array(v, np.int32)
            v[10], v[11] = 2 * nz, nx * ny * nz + int(frac.sum())
        elif name_ in ("SWAT", "SGAS", "PRESSURE", "RS"):
            f = v[frac] * 0.5 if name_ in ("SWAT", "SGAS") else v[frac] - 10
            v = np.concatenate([v, f.astype(v.dtype)])
        rst.append((k, v))
    _write(egrid.with_suffix(".UNRST"), rst)
    return egrid


def _read(path: Path) -> list:
    return [(k, np.array(v) if hasattr(v, "dtype") else v) for k, v in resfo.read(path)]


def _write(path: Path, records: list) -> None:
    tmp = path.with_name(path.name + ".part")
    resfo.write(tmp, [(k, v if not (isinstance(v, np.ndarray) and v.dtype.kind == "S")
                       else v.astype("S8")) for k, v in records])
    tmp.replace(path)


@made_once
def reek_grid_file(cache: Path = CACHE) -> Path:
    """The real Reek EGRID (ECLIPSE, shared data) as an old binary GRID file: ``REEK.GRID``,
    and ``corners.npy`` (xtgeo's corners, local coordinates: the oracle)."""
    folder = cache / "reek_grid_file"
    out = folder / "REEK.GRID"
    if out.is_file() and (folder / "corners.npy").is_file():
        return out
    src = SHARED / "reek_cornerpoint" / "model" / "2_R001_REEK-0.EGRID"
    if not src.is_file():
        raise CaseUnavailableError(f"the Reek EGRID {src} is absent (shared data)")
    try:
        import xtgeo
    except ImportError as err:
        raise CaseUnavailableError(f"xtgeo is not installed: {err}") from None
    folder.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = xtgeo.grid_from_file(src, relative_to="origin")
        nx, ny, nz = g.dimensions
        c = np.stack([p.values.data for p in g.get_xyz_corners()], -1).reshape(nx, ny, nz, 8, 3)
        act = np.asarray(g.get_actnum().values.filled(0))
    e = {k.strip(): v for k, v in _read(src)}
    recs = [("MAPUNITS", e["MAPUNITS"]), ("MAPAXES ", e["MAPAXES"]),
            ("GRIDUNIT", e["GRIDUNIT"]), ("DIMENS  ", np.int32([nx, ny, nz])),
            ("RADIAL  ", np.array([b"FALSE   "]))]
    n = 0
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                n += 1
                recs += [("COORDS  ", np.int32([i + 1, j + 1, k + 1, n, act[i, j, k], 0, 0])),
                         ("CORNERS ", c[i, j, k].astype(np.float32).ravel())]
    _write(out, recs)
    np.save(folder / "corners.npy", c)
    return out


#: the cells :func:`spe1_eclipse_style` makes inactive (0-based i, j, k)
INACTIVE = tuple((i, 0, 0) for i in range(10))


@made_once
def spe1_eclipse_style(cache: Path = CACHE) -> Path:
    """The SPE1 run with the row J=1, K=1 inactive as ECLIPSE writes it (ACTNUM 0, ZCORN 0 at
    their corners; INIT and UNRST arrays of the other cells) and SWL -1e20 (undefined) in its
    first 5 active cells: its EGRID."""
    folder = cache / "spe1_eclipse_style"
    egrid = folder / "ECLSTYLE.EGRID"
    if egrid.is_file() and (folder / "ECLSTYLE.UNRST").is_file():
        return egrid
    src = spe1_field(cache)
    folder.mkdir(parents=True, exist_ok=True)
    nx, ny, nz = 10, 10, 3
    act = np.ones((nx, ny, nz), bool)
    for c in INACTIVE:
        act[c] = False
    keep = act.reshape(-1, order="F")
    grid = []
    for k, v in _read(src):
        if k.strip() == "ACTNUM":
            v = keep.astype(np.int32)
        elif k.strip() == "ZCORN":
            z = np.array(v).reshape((2 * nx, 2 * ny, 2 * nz), order="F")
            dead = np.repeat(np.repeat(np.repeat(~act, 2, 0), 2, 1), 2, 2)
            z[dead] = 0.0
            v = z.reshape(-1, order="F")
        grid.append((k, v))
    _write(egrid, grid)
    for suffix in (".INIT", ".UNRST"):
        out = []
        for k, v in _read(src.with_suffix(suffix)):
            if k.strip() == "INTEHEAD":
                v = np.array(v, np.int32)
                v[11] = int(keep.sum())
            elif getattr(v, "size", 0) == nx * ny * nz and v.dtype.kind in "fi" and \
                    k.strip() != "PORV":
                v = v[keep]
            out.append((k, v))
            if suffix == ".INIT" and k.strip() == "PORO":
                swl = np.full(int(keep.sum()), 0.12, np.float32)
                swl[:5] = -1e20
                out.append(("SWL     ", swl))
        _write(egrid.with_suffix(suffix), out)
    return egrid


def main() -> None:
    for make in (spe1_lgr, spe1_hourly, spe1_dual, reek_grid_file, spe1_eclipse_style):
        try:
            print(make())
        except CaseUnavailableError as err:
            print(f"{make.__name__}: {err}")


if __name__ == "__main__":
    main()
