"""Architecture and style checks, run with the tests so CI enforces them."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_import_geoshade_does_not_import_moderngl():
    code = ("import sys, geoshade, geoshade.io, geoshade.compute.voxels.bitmaps, geoshade.models;"
            "geoshade.core; import geoshade.cli.main;"
            "sys.exit(1 if 'moderngl' in sys.modules else 0)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


@pytest.mark.skipif(shutil.which("lint-imports") is None, reason="import-linter not installed")
def test_layer_contracts():
    r = subprocess.run(["lint-imports"], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:]


@pytest.mark.skipif(shutil.which("ruff") is None, reason="ruff not installed")
def test_ruff_clean():
    r = subprocess.run(["ruff", "check", "--quiet", "."], cwd=ROOT, capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stdout[-3000:]


def test_source_files_stay_small():
    big = [p for p in (ROOT / "src").rglob("*.py") if len(p.read_text().splitlines()) > 800]
    assert not big, f"files over 800 lines: {big}"
