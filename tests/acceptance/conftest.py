"""Fixtures of the real-data acceptance suite: the cases, the CLI in-process, the viewer.

Each case is a public real data set: committed under ``tests/data/real/<case>/`` (with its
SOURCE.txt), made by :mod:`tests.acceptance.make_cases` from files a registry package ships, or
read in place from ``../shared/data``. A case that is not here skips its tests with the reason.
The pictures the tests draw are kept in ``tests/acceptance/.cache/pictures`` (git-ignored) so
that a person can look at them after a run.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.acceptance import make_cases
from tests.acceptance.make_cases import CACHE, REAL, SHARED, CaseUnavailableError

#: where the tests leave the pictures they draw, for a person to look at
PICTURES = CACHE / "pictures"


def _made(make, *args) -> Path:
    try:
        return make(*args)
    except CaseUnavailableError as err:
        pytest.skip(str(err))


@pytest.fixture(scope="session")
def real() -> Path:
    """``tests/data/real`` (the committed cases)."""
    return REAL


@pytest.fixture(scope="session")
def shared() -> Path:
    """``../shared/data``; skips when it is absent."""
    if not SHARED.is_dir():
        pytest.skip(f"real data folder {SHARED} is absent (see shared/data/README.md)")
    return SHARED


@pytest.fixture(scope="session")
def spe1() -> Path:
    """SPE1 (FIELD units, wells PROD and INJ) simulated by OPM Flow: its EGRID."""
    return _made(make_cases.spe1_field)


@pytest.fixture(scope="session")
def concrete() -> Path:
    """spam's X-ray tomogram of a concrete cylinder in air (100³ uint16 TIFF)."""
    return _made(make_cases.concrete_in_air)


@pytest.fixture(scope="session")
def dem() -> Path:
    """matplotlib's USGS DEM of the Jacksboro fault as an EPSG:4326 GeoTIFF."""
    return _made(make_cases.jacksboro_dem)


@pytest.fixture(scope="session")
def pictures() -> Path:
    """Folder where the tests keep their pictures (git-ignored)."""
    PICTURES.mkdir(parents=True, exist_ok=True)
    return PICTURES


class Cli:
    """``geoshade ...`` run in this process: exit code, stdout, stderr; the stats JSON read."""

    def __init__(self, capsys, pictures: Path, tmp_path: Path):
        self.capsys = capsys
        self.pictures = pictures
        self.tmp = tmp_path

    def __call__(self, *args: str) -> tuple[int, str, str]:
        from geoshade.cli.main import main

        self.capsys.readouterr()
        rc = main([str(a) for a in args])
        out, err = self.capsys.readouterr()
        return rc, out, err

    def render(self, name: str, *args: str) -> dict:
        """Run a render subcommand writing ``<pictures>/<name>.png``; its stats JSON."""
        png = self.pictures / f"{name}.png"
        stats = self.tmp / f"{name}.json"
        rc, out, err = self(*args, "-o", png, "--stats", stats)
        assert rc == 0, err
        assert png.is_file(), out
        return json.loads(stats.read_text())


@pytest.fixture
def cli(capsys, pictures, tmp_path) -> Cli:
    """The CLI in-process (see :class:`Cli`)."""
    return Cli(capsys, pictures, tmp_path)


def view_screenshot(pictures: Path, name: str, *args: str, size: str = "480x360") -> np.ndarray:
    """``geoshade view ARGS --screenshot`` in a subprocess (Qt offscreen); the RGBA picture."""
    pytest.importorskip("PySide6", reason="the desktop viewer needs PySide6 (geoshade[viewer])")
    png = pictures / f"{name}.png"
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    r = subprocess.run([sys.executable, "-m", "geoshade.cli.main", "view", *map(str, args),
                        "--screenshot", str(png), "--size", size], env=env,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGBA"))


def annotations(stats: dict) -> dict:
    """The annotation layout of a render's stats (title lines, colour bar, legend, labels)."""
    assert "annotations" in stats, sorted(stats)
    return stats["annotations"]


def title_text(stats: dict) -> str:
    """Every title line of a render, joined by newlines."""
    return "\n".join(t["text"] for t in annotations(stats).get("title", []))


def legend_entries(stats: dict) -> list[str]:
    """The legend's entry texts of a render (empty when it has none)."""
    legend = annotations(stats).get("legend") or {}
    return [str(e.get("text", e.get("label", ""))) for e in legend.get("entries", [])]


def legend_names(stats: dict) -> list[str]:
    """The legend's entries without a leading code ("0 SHALE" -> "SHALE")."""
    return [re.sub(r"^-?\d+\s+", "", text) for text in legend_entries(stats)]


def colorbar_label(stats: dict) -> str:
    """The colour bar's label of a render ('' when it has none)."""
    bar = annotations(stats).get("colorbar") or {}
    return str(bar.get("label", ""))


def inside_picture(stats: dict, bbox) -> bool:
    """Whether a bounding box (x, y, w, h) lies inside the picture."""
    x, y, w, h = bbox
    return x >= 0 and y >= 0 and x + w <= stats["width"] + 0.5 and y + h <= stats["height"] + 0.5
