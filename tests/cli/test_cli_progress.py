"""The CLI's one progress bar (tqdm over the progress protocol) and where the CLI uses it."""

from __future__ import annotations

import io

import pytest

from geoshade.cli import progress as cli_progress
from geoshade.cli.main import main
from geoshade.compute.grid.synthetic import synthetic_grid
from geoshade.io.grids.grdecl_writer import write_grdecl


def test_bar_units_resize_and_close(monkeypatch):
    import tqdm

    made = []
    real = tqdm.tqdm

    def spy(*a, **kw):
        kw.update(file=io.StringIO(), disable=False)
        made.append(real(*a, **kw))
        return made[-1]

    monkeypatch.setattr(tqdm, "tqdm", spy)
    with cli_progress.progress_bar("reading", unit="bytes") as cb:
        cb(100, 1000)
        cb(1000, 1500)  # an INCLUDE found: the total grows
        cb(1500, 1500)
        bar = made[0]
        assert bar.unit == "B" and bar.unit_scale and bar.total == 1500 and bar.n == 1500
    assert len(made) == 1 and bar.disable  # closed at the end (tqdm disables a closed bar)
    with cli_progress.progress_bar("steps", unit="steps") as cb:
        cb(1, 3)
    assert made[1].unit == "step"
    with cli_progress.progress_bar("nothing reported"):
        pass
    assert len(made) == 2  # no report, no bar


def test_unknown_unit_is_refused():
    with pytest.raises(ValueError, match="unit must be one of"), \
            cli_progress.progress_bar("x", unit="furlongs"):
        pass


def test_info_reads_a_grid_with_progress(capsys, tmp_path, monkeypatch):
    f = write_grdecl(synthetic_grid(4, 3, 2), tmp_path / "g.grdecl")
    import contextlib

    import geoshade.cli.info as info

    units, calls = [], []

    @contextlib.contextmanager
    def spy(desc, unit="slabs"):
        units.append(unit)
        yield lambda d, t: calls.append((d, t))

    monkeypatch.setattr(info, "progress_bar", spy)
    assert main(["info", str(f)]) == 0
    size = f.stat().st_size
    assert units == ["bytes"] and calls[-1] == (size, size)
    assert "4" in capsys.readouterr().out
