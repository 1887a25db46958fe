"""``geoshade iso`` on reservoir cases as users have them (issue 14): a ``.DATA`` deck read as
``grid render`` reads it (static properties through ``geoshade.load``), the open surface at
inactive cells by default and ``--caps``; one clear line for each bad input."""

from __future__ import annotations

import json
import warnings

import pytest
from PIL import Image

from geoshade.cli.main import main
from geoshade.compute.mesh import marching_cubes as mc

REEK_DECK = "reek_cornerpoint/model/2_R001_REEK-0.DATA"
REEK_EGRID = "reek_cornerpoint/opm_flow_run/2_R001_REEK-0.EGRID"


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def deck_counts(path, keyword, level) -> tuple[int, int]:
    """(open, closed) triangles of ``keyword`` = ``level`` of a deck, on the CPU."""
    import geoshade
    from geoshade.iso.api import field_of

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = field_of(geoshade.load(path), keyword)
    pv = mc.prepare_values(f.step(0), f.active)
    return mc.triangle_count(pv, level), mc.triangle_count(pv, level, caps=True)


@pytest.fixture(scope="module")
def deck(tmp_path_factory):
    """A deck (RUNSPEC/GRID/INCLUDE of a GRDECL with inactive blobs) and nothing beside it."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    d = tmp_path_factory.mktemp("deck")
    g = synthetic_grid(14, 12, 6, steps=0, inactive_fraction=0.15, seed=2)
    write_grdecl(g, d / "grid.grdecl")
    nx, ny, nz = g.dims
    (d / "CASE.DATA").write_text(f"RUNSPEC\nDIMENS\n {nx} {ny} {nz} /\nMETRIC\nGRID\n"
                                 "INCLUDE\n 'grid.grdecl' /\nEND\n")
    return d / "CASE.DATA"


@pytest.mark.gl
def test_render_a_deck_by_keyword_open_and_capped(capsys, tmp_path, deck):
    level = 0.2
    opened, closed = deck_counts(deck, "PORO", level)
    assert 0 < opened < closed
    for extra, want in (((), opened), (("--caps",), closed)):
        out, stats = tmp_path / "o.png", tmp_path / "s.json"
        rc, text, err = run(capsys, "iso", "render", deck, "--keyword", "poro", "--level", level,
                            "--size", "80x60", "--frames", 1, "--stats", stats, "-o", out,
                            *extra)
        assert rc == 0, err
        st = json.loads(stats.read_text())
        assert st["triangles"] == want and st["caps"] is bool(extra)
        assert st["name"] == "PORO" and st["nsteps"] == 1 and st["inactive"] > 0
        assert Image.open(out).size == (80, 60)
        assert "PORO = 0.2" in text


@pytest.mark.gl
def test_deck_errors_are_one_line(capsys, tmp_path, deck):
    rc, _, err = run(capsys, "iso", "render", deck, "--level", 0.2, "-o", tmp_path / "o.png")
    assert rc == 2 and "no SWAT (the default keyword) and no report steps" in err
    assert "--keyword" in err and "PORO" in err and len(err.strip().splitlines()) == 1
    rc, _, err = run(capsys, "iso", "render", deck, "--keyword", "PORO", "--level", 0.2,
                     "--spacing", 1, 1, 1, "-o", tmp_path / "o.png")
    assert rc == 2 and "--spacing does not apply to a deck" in err
    assert len(err.strip().splitlines()) == 1
    rc, _, err = run(capsys, "iso", "render", deck, "--keyword", "PORO", "--level", 0.2,
                     "--step", 3, "-o", tmp_path / "o.png")
    assert rc == 2 and "step 3" in err and len(err.strip().splitlines()) == 1
    rc, _, err = run(capsys, "iso", "render", deck, "--keyword", "NOPE", "--level", 0.2,
                     "-o", tmp_path / "o.png")
    assert rc == 2 and "NOPE" in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.gl
def test_animate_a_deck(capsys, tmp_path, deck):
    out = tmp_path / "a.gif"
    rc, _, err = run(capsys, "iso", "animate", deck, "--keyword", "PORO", "--level", 0.2,
                        "--size", "64x48", "-o", out, "--stats", tmp_path / "s.json")
    assert rc == 0, err
    st = json.loads((tmp_path / "s.json").read_text())
    assert st["frames"] == 1 and st["triangles"] == [deck_counts(deck, "PORO", 0.2)[0]]
    with Image.open(out) as im:
        assert im.n_frames == 1 and im.size == (64, 48)


@pytest.mark.gl
@pytest.mark.data
def test_reek_deck_by_keyword(capsys, tmp_path, shared_data):
    """The Reek deck (an EGRID beside it but no INIT: no run) reads as ``grid render`` reads
    it."""
    deck = shared_data / REEK_DECK
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc, _, err = run(capsys, "iso", "render", deck, "--keyword", "PORO", "--level", 0.2,
                     "--size", "80x60", "--frames", 1, "--stats", stats, "-o", out)
    assert rc == 0, err
    st = json.loads(stats.read_text())
    assert st["triangles"] == deck_counts(deck, "PORO", 0.2)[0] > 1000


@pytest.mark.gl
@pytest.mark.data
def test_reek_run_open_by_default_caps_on_request(capsys, tmp_path, shared_data):
    from geoshade.io import load_field

    f = load_field(shared_data / REEK_EGRID, step=36)
    pv = mc.prepare_values(f.step(0), f.active)
    for extra, caps in (((), False), (("--caps",), True)):
        rc, _, err = run(capsys, "iso", "render", shared_data / REEK_EGRID, "--level", 0.5,
                         "--step", 36, "--size", "80x60", "--frames", 1, "--stats",
                         tmp_path / "s.json", "-o", tmp_path / "o.png", *extra)
        assert rc == 0, err
        st = json.loads((tmp_path / "s.json").read_text())
        assert st["caps"] is caps
        assert st["triangles"] == mc.triangle_count(pv, 0.5, caps=caps)


@pytest.mark.parametrize("beside", [(), (".EGRID",), (".EGRID", ".INIT")])
def test_a_deck_is_read_as_its_run_only_when_the_run_is_beside_it(tmp_path, beside):
    from geoshade.errors import InputError
    from geoshade.io.fields import is_bare_deck, load_field

    deck = tmp_path / "CASE.DATA"
    deck.write_text("RUNSPEC\n")
    for ext in beside:
        (tmp_path / f"CASE{ext}").write_bytes(b"")
    assert is_bare_deck(deck) is (len(beside) < 2)
    if len(beside) < 2:
        with pytest.raises(InputError, match=r"a deck without its run .* geoshade\.load"):
            load_field(deck)
