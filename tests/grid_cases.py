"""The benchmark's independent case writer (``benchmarks/grid_cases.py``) for the tests that read
its ECLIPSE/GRDECL files."""

from __future__ import annotations

import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def grid_cases():
    """The ``benchmarks/grid_cases`` module (imported once from the benchmarks folder)."""
    if "grid_cases" in sys.modules:
        return sys.modules["grid_cases"]
    sys.path.insert(0, str(BENCH))
    try:
        import grid_cases
    finally:
        sys.path.remove(str(BENCH))
    return grid_cases
