"""The models' conversion methods reach io/interop through a registry filled downward."""

import subprocess
import sys


def _run(code: str) -> str:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip()


def test_io_registers_the_converters():
    out = _run("import numpy as np, sys\n"
               "from geoshade.models import VoxelVolume\n"
               "import geoshade.io\n"
               "from geoshade.models.convert import CONVERTERS\n"
               "print(sorted(CONVERTERS), 'geoshade.api' in sys.modules,\n"
               "      VoxelVolume(np.zeros((1, 2, 3), np.uint8)).to_xarray().dims)")
    assert out == "['to_pyvista', 'to_xarray'] False ('z', 'y', 'x')"


def test_api_units_win_for_a_grid():
    import geoshade.api  # noqa: F401
    from geoshade.compute.synthetic_grid import synthetic_grid

    assert synthetic_grid(3, 2, 2).to_xarray("PERMX").attrs["units"] == "mD"


def test_unregistered_converter_is_one_line():
    out = _run("from geoshade.models import VoxelVolume\nimport numpy as np\n"
               "from geoshade.errors import InputError\n"
               "try:\n    VoxelVolume(np.zeros((1, 1, 1), np.uint8)).to_xarray()\n"
               "except InputError as e:\n    print(e)")
    assert out.startswith("VoxelVolume.to_xarray: no converter is registered")
