"""``geoshade info / grid render / iso render`` on decks as users have them: missing INCLUDEs
(``--skip-missing``), geometry lost (IJK index space), block-centred decks, units."""

from __future__ import annotations

import json

import pytest

from geoshade.cli.main import build_parser, main
from tests.io.test_missing_includes import MISSING, N_FAULTS, field_deck


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def _lines(err: str, kind: str) -> list[str]:
    return [ln for ln in err.splitlines() if ln.startswith(f"geoshade: {kind}:")]


def test_info_complete_deck(capsys, tmp_path):
    deck, _ = field_deck(tmp_path)
    rc, out, err = run(capsys, "info", deck)
    assert rc == 0, err
    assert f"  faults   {N_FAULTS}: F_A1" in out and "  units    FIELD (lengths in FEET)" in out
    assert "  property PERMY" in out and "missing" not in out
    assert "  skipped  " in out  # keywords the grid reader does not use (PVDO, EQUIL, ...)


def test_info_lists_every_missing_include(capsys, tmp_path):
    deck, _ = field_deck(tmp_path, MISSING)
    rc, out, err = run(capsys, "info", deck)
    assert rc == 2
    errors = _lines(err, "error")
    assert len(errors) == 1 and errors[0].startswith(f"geoshade: error: {deck}: 4 INCLUDE files "
                                                      "are missing: ")
    assert all(n in errors[0] for n in MISSING) and errors[0].endswith(
        "; --skip-missing reads the rest")
    assert not any("missing and skipped" in w for w in _lines(err, "warning"))
    # ... after everything it could read
    assert "  missing  4 INCLUDE files: " in out and "  property PERMX" in out
    assert "  property PERMY" not in out and f"  faults   {N_FAULTS - 5}: " in out

    rc, out, err = run(capsys, "info", "--skip-missing", "--json", deck)
    assert rc == 0 and not _lines(err, "error")
    skipped = [w for w in _lines(err, "warning") if "missing and skipped" in w]
    assert len(skipped) == 1 and all(n in skipped[0] for n in MISSING)
    d = json.loads(out)
    assert len(d["missing_includes"]) == 4 and d["unit_system"] == "FIELD"
    assert len(d["faults"]) == N_FAULTS - 5 and "PERMY" not in d["properties"]


def test_info_index_space(capsys, tmp_path):
    deck, _ = field_deck(tmp_path, ("grid/coord.inc",))
    rc, out, err = run(capsys, "info", "--skip-missing", deck)
    assert rc == 0, err
    assert "  geometry IJK index space: no geometry was read, unit cells" in out
    assert "depth 0..4 (cells)" in out
    warn = [w for w in _lines(err, "warning") if "IJK index space" in w]
    assert len(warn) == 1 and "'../include/grid/coord.inc'" in warn[0]


def test_skip_missing_is_for_decks(capsys, tmp_path):
    raw = tmp_path / "v.raw"
    raw.write_bytes(bytes(24))
    rc, _, err = run(capsys, "info", raw, "--shape", 2, 3, 4, "--dtype", "uint8",
                     "--skip-missing")
    assert rc == 2 and "skip_missing does not apply to this file type" in err
    for argv in (["grid", "render", "C.DATA", "-o", "x.png"],
                 ["iso", "render", "C.DATA", "--level", "0.5", "-o", "x.png"],
                 ["view", "C.DATA"]):
        assert build_parser().parse_args([*argv, "--skip-missing"]).skip_missing


@pytest.mark.gl
def test_grid_render_skip_missing(capsys, tmp_path):
    deck, _ = field_deck(tmp_path, ("grid/zcorn.inc", *MISSING))
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    argv = ("grid", "render", deck, "--property", "PORO", "--size", "160x120", "--frames", 1,
            "-o", out, "--stats", stats)
    rc, _, err = run(capsys, *argv)
    assert rc == 2 and "5 INCLUDE files are missing" in err and not out.exists()
    rc, _, err = run(capsys, *argv, "--skip-missing")
    assert rc == 0, err
    skipped = [w for w in _lines(err, "warning") if "missing and skipped" in w]
    assert len(skipped) == 1 and "IJK index space" in skipped[0]
    s = json.loads(stats.read_text())
    assert s["faces_drawn"] > 0 and s["property"] == "PORO"


@pytest.mark.gl
def test_block_centred_deck_renders(capsys, tmp_path):
    from tests.io.test_block_centred import SPE1, SPE1_GRID, _deck

    deck = _deck(tmp_path / "SPE1.DATA", SPE1, SPE1_GRID, "FIELD")
    out, stats = tmp_path / "o.png", tmp_path / "s.json"
    rc, _, err = run(capsys, "grid", "render", deck, "--property", "PERMX", "--size", "160x120",
                     "--frames", 1, "-o", out, "--stats", stats)
    assert rc == 0, err
    assert json.loads(stats.read_text())["cells"] == 300
    rc, _, err = run(capsys, "iso", "render", deck, "--keyword", "PORO", "--level", "0.1",
                     "--skip-missing", "--size", "160x120", "--frames", 1, "-o", out)
    assert rc == 0, err
