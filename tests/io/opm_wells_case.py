"""A small SPE1-like case (8×6×3 block-centred cells, 3 wells, 5 report steps) simulated with
OPM Flow from PyPI (``pip install opm opm-simulators``): real IWEL/ICON/ZWEL records.

Schedule (report step: what changes):

- 1: PROD (producer, completions (8,6,2) (8,6,3)), GINJ (gas injector, (1,1,1) (1,1,2)) and
  WINJ (water injector, (1,6,3)) open (1-based I J K);
- 2: GINJ's completion (1,1,2) shut;
- 3: WINJ shut;
- 4: WINJ open again.

:func:`opm_case` runs it once per session (in a subprocess, timed out after 5 minutes) and
skips the test with the reason when OPM Flow cannot be imported or run.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

GRID = """RUNSPEC
TITLE
 SIMULATION WELLS TEST
DIMENS
 8 6 3 /
OIL
WATER
GAS
DISGAS
FIELD
START
 1 'JAN' 2015 /
WELLDIMS
 3 3 1 3 /
TABDIMS
 1 1 15 15 2 15 /
EQLDIMS
 1 /
UNIFOUT
GRID
INIT
DX
 144*1000 /
DY
 144*1000 /
DZ
 48*20 48*30 48*50 /
TOPS
 48*8325 /
PORO
 144*0.3 /
PERMX
 48*500 48*50 48*200 /
PERMY
 48*500 48*50 48*200 /
PERMZ
 48*500 48*50 48*200 /
"""

PROPS = """PROPS
PVTW
 4017.55 1.038 3.22E-6 0.318 0.0 /
ROCK
 14.7 3E-6 /
SWOF
0.12 0 1 0
0.18 4.64876e-08 1 0
0.24 0.000000186 0.997 0
0.3 4.18e-07 0.98 0
0.36 7.44e-07 0.7 0
0.42 1.16e-06 0.35 0
0.48 1.67e-06 0.2 0
0.54 2.28e-06 0.09 0
0.6 2.98e-06 0.021 0
0.66 3.77e-06 0.01 0
0.72 4.65e-06 0.001 0
0.78 5.63e-06 0.0001 0
0.84 6.7e-06 0 0
0.91 8.37e-06 0 0
1 0.0000105 0 0 /
SGOF
0 0 1 0
0.001 0 1 0
0.02 0 0.997 0
0.05 0.005 0.980 0
0.12 0.025 0.700 0
0.2 0.075 0.350 0
0.25 0.125 0.200 0
0.3 0.190 0.090 0
0.4 0.410 0.021 0
0.45 0.60 0.010 0
0.5 0.72 0.001 0
0.6 0.87 0.0001 0
0.7 0.94 0.000 0
0.85 0.98 0.000 0
0.88 0.984 0.000 0 /
DENSITY
 53.66 64.49 0.0533 /
PVDG
14.700 166.666 0.008000
264.70 12.0930 0.009600
514.70 6.27400 0.011200
1014.7 3.19700 0.014000
2014.7 1.61400 0.018900
2514.7 1.29400 0.020800
3014.7 1.08000 0.022800
4014.7 0.81100 0.026800
5014.7 0.64900 0.030900
9014.7 0.38600 0.047000 /
PVTO
0.0010 14.7 1.0620 1.0400 /
0.0905 264.7 1.1500 0.9750 /
0.1800 514.7 1.2070 0.9100 /
0.3710 1014.7 1.2950 0.8300 /
0.6360 2014.7 1.4350 0.6950 /
0.7750 2514.7 1.5000 0.6410 /
0.9300 3014.7 1.5650 0.5940 /
1.2700 4014.7 1.6950 0.5100
 9014.7 1.5790 0.7400 /
1.6180 5014.7 1.8270 0.4490
 9014.7 1.7370 0.6310 /
/
SOLUTION
EQUIL
 8400 4800 8450 0 8300 0 1 0 0 /
RSVD
8300 1.270
8450 1.270 /
SUMMARY
FOPR
"""

SCHEDULE = """SCHEDULE
RPTRST
 'BASIC=1' /
WELSPECS
 'PROD' 'G1' 8 6 8400 'OIL' /
 'GINJ' 'G1' 1 1 8335 'GAS' /
 'WINJ' 'G1' 1 6 8335 'WATER' /
/
COMPDAT
 'PROD' 8 6 2 3 'OPEN' 1* 1* 0.5 /
 'GINJ' 1 1 1 2 'OPEN' 1* 1* 0.5 /
 'WINJ' 1 6 3 3 'OPEN' 1* 1* 0.5 /
/
WCONPROD
 'PROD' 'OPEN' 'ORAT' 20000 4* 1000 /
/
WCONINJE
 'GINJ' 'GAS' 'OPEN' 'RATE' 100000 1* 9014 /
 'WINJ' 'WATER' 'OPEN' 'RATE' 5000 1* 9014 /
/
TSTEP
 31 /
WELOPEN
 'GINJ' 'SHUT' 1 1 2 /
/
TSTEP
 28 /
WELOPEN
 'WINJ' 'SHUT' /
/
TSTEP
 31 /
WELOPEN
 'WINJ' 'OPEN' /
/
TSTEP
 30 /
END
"""

DECK = GRID + PROPS + SCHEDULE

#: what the schedule gives, per report step: well -> (type, open, [(i, j, k, open)]) 0-based
EXPECTED = {
    1: {"PROD": ("producer", True, [(7, 5, 1, True), (7, 5, 2, True)]),
        "GINJ": ("gas injector", True, [(0, 0, 0, True), (0, 0, 1, True)]),
        "WINJ": ("water injector", True, [(0, 5, 2, True)])},
}
EXPECTED[2] = {**EXPECTED[1], "GINJ": ("gas injector", True, [(0, 0, 0, True),
                                                              (0, 0, 1, False)])}
EXPECTED[3] = {**EXPECTED[2], "WINJ": ("water injector", False, [(0, 5, 2, True)])}
EXPECTED[4] = {**EXPECTED[2]}

_RUN = """
import sys
from opm.simulators import BlackOilSimulator
sim = BlackOilSimulator(sys.argv[1])
sim.step_init()
while not sim.check_simulation_finished():
    sim.step()
sim.step_cleanup()
"""

_CACHE: dict[str, Path] = {}


def opm_case(tmp_path_factory) -> Path:
    """The EGRID of the simulated case (UNRST and INIT beside it); skips without OPM Flow."""
    if "egrid" in _CACHE:
        return _CACHE["egrid"]
    if "skip" in _CACHE:
        pytest.skip(str(_CACHE["skip"]))
    try:
        import opm.simulators  # noqa: F401
    except ImportError as err:
        _CACHE["skip"] = Path(f"OPM Flow is not installed (pip install opm opm-simulators): "
                              f"{err}")
        pytest.skip(str(_CACHE["skip"]))
    folder = tmp_path_factory.mktemp("opm_wells")
    deck = folder / "SIMW.DATA"
    deck.write_text(DECK)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    try:
        run = subprocess.run([sys.executable, "-c", _RUN, str(deck)], cwd=folder, env=env,
                             capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        run = None
    egrid = folder / "SIMW.EGRID"
    if run is None or run.returncode != 0 or not (folder / "SIMW.UNRST").exists():
        tail = "" if run is None else (run.stderr or run.stdout)[-300:]
        _CACHE["skip"] = Path(f"OPM Flow did not run the test deck: {tail or 'timed out'}")
        pytest.skip(str(_CACHE["skip"]))
    _CACHE["egrid"] = egrid
    return egrid
