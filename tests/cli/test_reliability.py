"""Issue 12, the adapters' half: outputs checked before any work and written together at the end,
inputs never overwritten, OS errors and bad arguments in one line, a closed stdout quiet, a bug
reported as a bug (exit 70, the traceback in a file)."""

from __future__ import annotations

import errno
import io

import numpy as np
import pytest

from geoshade.cli.main import main
from tests.corruption import BUG_EXIT, Tally, clean_failure, file_hashes, listing, run_cli

RAW = ("--shape", 12, 10, 8, "--dtype", "uint8")


@pytest.fixture
def raw(tmp_path):
    p = tmp_path / "vol.raw"
    np.random.default_rng(0).integers(0, 255, (8, 10, 12)).astype(np.uint8).tofile(p)
    return p


@pytest.fixture
def field(tmp_path):
    p = tmp_path / "sw.npz"
    np.savez(p, SWAT=np.random.default_rng(1).random((2, 4, 5, 6)).astype(np.float32))
    return p


@pytest.fixture
def grdecl(tmp_path):
    """A GRDECL case with an INCLUDE file named like an output could be."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    g = synthetic_grid(5, 4, 3, seed=1)
    inc = tmp_path / "props.json"   # a data file whose name an output could take
    write_grdecl(g, inc)
    deck = tmp_path / "case.grdecl"
    deck.write_text(f"INCLUDE\n'{inc.name}' /\n")
    return deck, inc


TALLY = Tally("adapters")

# --- 1. data loss: an output that names an input is refused before any work -------------------
DATA_LOSS = [
    (("core", "render", "IN", *RAW, "-o", "IN"), "expected a name ending in .png"),
    (("core", "porosity", "IN", *RAW, "--select", 0, 9, "-o", "p.png", "--csv", "IN"),
     "expected a name ending in .csv"),
    (("core", "porosity", "IN", *RAW, "--select", 0, 9, "-o", "p.png", "--json", "p.png"),
     "--json: expected a name ending in .json"),
    (("core", "porosity", "IN", *RAW, "--select", 0, 9, "-o", "p.png", "--csv", "p.csv",
      "--json", "IN.json"), None),
]


@pytest.mark.parametrize(("argv", "expect"), DATA_LOSS[:3])
def test_outputs_naming_inputs_or_each_other_are_refused(capsys, tmp_path, raw, argv, expect):
    argv = [str(raw) if a == "IN" else (tmp_path / a if isinstance(a, str) and "." in a
                                        and a.endswith(("png", "csv", "json")) else a)
            for a in argv]
    line = clean_failure(capsys, argv, inputs=[raw], watch=[tmp_path], names="",
                         expect=expect)
    TALLY(bool(line))


def test_grid_case_files_and_includes_are_protected(capsys, tmp_path, grdecl):
    deck, inc = grdecl
    out = tmp_path / "o.png"
    line = clean_failure(capsys, ["grid", "render", deck, "-o", out, "--stats", inc],
                         inputs=[deck, inc], watch=[tmp_path], names="props.json",
                         expect="--stats names an input (props.json)")
    assert not out.exists()
    TALLY(bool(line))


def test_an_egrid_case_protects_its_init_and_unrst(capsys, tmp_path):
    """``grid render A.EGRID --stats A.INIT``-like names: every file of the case is an input."""
    case = tmp_path / "A.EGRID"
    case.write_bytes(b"not read")
    init = tmp_path / "A.json"      # a case file with an output's suffix
    init.write_text("{}")
    line = clean_failure(capsys, ["grid", "render", case, "-o", tmp_path / "o.png",
                                  "--stats", init], inputs=[case, init], watch=[tmp_path],
                         names="A.json", expect="names an input")
    TALLY(bool(line))


def test_an_output_inside_an_input_store_is_refused(capsys, tmp_path):
    from geoshade.compute.voxels.synthetic import synthetic_core
    from geoshade.io import write_zarr

    store = tmp_path / "core.zarr"
    write_zarr(synthetic_core(16), store)
    line = clean_failure(capsys, ["core", "porosity", store, "--select", 0, 9000,
                                  "-o", store / "p.png"], inputs=[store], watch=[tmp_path],
                         names="p.png", expect="names an input (core.zarr)")
    TALLY(bool(line))


# --- 5. OS errors on write ----------------------------------------------------------------------
@pytest.mark.parametrize(("out", "expect"), [
    ("", "-o: expected a file name, got an empty string"),
    ("FOLDER", "-o names a folder"),
    ("missing/o.png", "the folder"),
])
def test_bad_output_paths_are_one_line(capsys, tmp_path, raw, out, expect):
    target = "" if out == "" else str(tmp_path) if out == "FOLDER" else str(tmp_path / out)
    line = clean_failure(capsys, ["core", "porosity", raw, *RAW, "--select", 0, 9, "-o", target],
                         inputs=[raw], watch=[tmp_path], names="", expect=expect)
    TALLY(bool(line))


def test_read_only_folder(capsys, tmp_path, raw, monkeypatch):
    import os

    real = os.access
    monkeypatch.setattr(os, "access", lambda p, m, *a, **k: False if str(p) == str(tmp_path / "ro")
                        else real(p, m, *a, **k))
    (tmp_path / "ro").mkdir()
    line = clean_failure(capsys, ["core", "porosity", raw, *RAW, "--select", 0, 9,
                                  "-o", tmp_path / "ro" / "p.png"], inputs=[raw],
                         watch=[tmp_path], names="p.png", expect="is not writable")
    TALLY(bool(line))


def test_disk_full_while_writing_leaves_nothing(capsys, tmp_path, raw, monkeypatch):
    """ENOSPC while the outputs are staged: one line, exit 74, no file (not even the PNG)."""
    from geoshade.io import output

    real_put = output.Outputs.put

    def full(self, flag, data):
        if flag == "--json":
            raise OSError(errno.ENOSPC, "No space left on device", str(self.paths[flag]))
        return real_put(self, flag, data)

    monkeypatch.setattr(output.Outputs, "put", full)
    seen = listing([tmp_path])
    rc, _, err = run_cli(capsys, ["core", "porosity", raw, *RAW, "--select", 0, 9,
                                  "-o", tmp_path / "p.png", "--json", tmp_path / "p.json"])
    assert rc == 74 and err.strip().endswith("p.json: no space left on device"), err
    assert len(err.strip().splitlines()) == 1 and listing([tmp_path]) == seen
    TALLY(True)


# --- 6. outputs checked before the work, all written at the end -------------------------------
@pytest.mark.gl
def test_a_bad_stats_path_fails_before_the_render(capsys, tmp_path, raw, monkeypatch):
    import geoshade.core.view as core_view

    monkeypatch.setattr(core_view.CoreView, "draw", lambda *a, **k: pytest.fail("rendered"))
    line = clean_failure(capsys, ["core", "render", raw, *RAW, "-o", tmp_path / "o.png",
                                  "--stats", tmp_path / "nowhere" / "s.json"], inputs=[raw],
                         watch=[tmp_path], names="s.json", expect="does not exist")
    TALLY(bool(line))


@pytest.mark.gl
def test_a_failure_after_the_render_leaves_no_picture(capsys, tmp_path, raw, monkeypatch):
    from geoshade.cli import render
    from geoshade.io import output

    def broken(obj):
        raise OSError(errno.EIO, "Input/output error", "s.json")

    monkeypatch.setattr(output, "json_bytes", broken)
    monkeypatch.setattr(render, "json_bytes", broken)   # imported at the module's top
    seen = listing([tmp_path])
    rc, _, err = run_cli(capsys, ["core", "render", raw, *RAW, "--size", "32x24", "--frames", 1,
                                  "-o", tmp_path / "o.png", "--stats", tmp_path / "s.json"])
    assert rc == 74 and listing([tmp_path]) == seen, err
    TALLY(True)


def test_stacks_convert_writes_nothing_when_it_fails(capsys, tmp_path):
    """The model used to be written before a later step crashed (an all-NaN variable)."""
    a = np.full((6, 4, 5), np.nan, np.float32)
    src = tmp_path / "labels.npy"
    np.save(src, a)
    line = clean_failure(capsys, ["stacks", "convert", src, "-o", tmp_path / "m.stacks.npz",
                                  "--stats", tmp_path / "c.json"], inputs=[src],
                         watch=[tmp_path], names="labels.npy")
    TALLY(bool(line))


# --- 8. numbers and arguments -------------------------------------------------------------------
BAD_ARGS = [
    (("core", "render", "IN", *RAW, "--azimuth", "inf", "-o", "o.png"), "--azimuth"),
    (("core", "render", "IN", *RAW, "--gpu-memory", "nan", "-o", "o.png"), "--gpu-memory"),
    (("core", "render", "IN", *RAW, "--zoom", "0", "-o", "o.png"), "zoom"),
    (("core", "render", "IN", *RAW, "--frames", "0", "-o", "o.png"), "--frames"),
    (("core", "render", "IN", *RAW, "--size", "0x9", "-o", "o.png"), "size"),
    (("core", "render", "IN", *RAW, "--elevation", "91", "-o", "o.png"), "elevation"),
    (("core", "render", "IN", *RAW, "--select", "nan", "3", "-o", "o.png"), "--select"),
    (("core", "render", "IN", *RAW, "--box", "-1", "0", "0", "4", "4", "4", "-o", "o.png"),
     "box"),
    (("core", "porosity", "IN", *RAW, "--select", "0", "9", "-o", "p.png", "--scheduler",
      "junk"), "scheduler 'junk'"),
    (("core", "render", "IN", "--shape", "0", "10", "8", "--dtype", "uint8", "-o", "o.png"),
     "shape"),
    (("core", "render", "IN", *RAW, "--spacing", "1", "-2", "1", "-o", "o.png"), "spacing"),
    (("iso", "render", "IN", "--level", "inf", "-o", "o.png"), "--level"),
    (("iso", "render", "IN", "--level", "0.5", "--patch-level", "-1", "-o", "o.png"),
     "--patch-level"),
    (("iso", "animate", "IN", "--level", "0.5", "--fps", "0", "-o", "a.gif"), "fps"),
    (("grid", "render", "IN", "--exaggeration", "nan", "-o", "o.png"), "--exaggeration"),
    (("stacks", "render", "IN", "--smooth", "-1", "-o", "o.png"), "smooth"),
]


@pytest.mark.parametrize(("argv", "expect"), BAD_ARGS,
                         ids=[" ".join(str(a) for a in x[1:2]) + f"-{i}"
                              for i, (x, _) in enumerate(BAD_ARGS)])
def test_bad_numbers_are_one_line(capsys, tmp_path, raw, field, argv, expect):
    src = field if argv[0] == "iso" else raw
    argv = [str(src) if a == "IN" else (tmp_path / a if a in ("o.png", "p.png", "a.gif")
                                        else a) for a in argv]
    before = file_hashes([raw])
    try:
        rc, _, err = run_cli(capsys, argv)
    except SystemExit as stop:  # argparse: one line, status 2
        rc, err = stop.code, capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("geoshade: error:"), err
    assert expect in lines[0] and "Traceback" not in err, err
    assert file_hashes([raw]) == before and not list(tmp_path.glob("*.png"))
    assert not list(tmp_path.glob("*.gif"))
    TALLY(True)


def test_argparse_errors_are_one_line(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["core", "render", "x.raw", "--frames", "many", "-o", "o.png"])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1, err
    assert err.startswith("geoshade: error: geoshade core render: argument --frames: expected "
                          "an integer >= 1, got 'many'")


# --- 10. around the edges -------------------------------------------------------------------------
def test_a_closed_stdout_ends_quietly(capsys, monkeypatch, tmp_path):
    class Closed(io.StringIO):
        def write(self, s):
            raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    f = tmp_path / "v.npy"
    np.save(f, np.zeros((3, 4, 5), np.uint8))
    monkeypatch.setattr("sys.stdout", Closed())
    rc = main(["info", str(f), "--json"])
    assert rc == 141 and capsys.readouterr().err == ""


def test_info_json_into_head_has_no_traceback(tmp_path):
    """``geoshade info --json FILE | head -c 20``: the reader of the pipe stops early."""
    import subprocess
    import sys

    f = tmp_path / "wide.npz"
    np.savez(f, data=np.zeros((3, 3, 3), np.uint8))
    cmd = (f"{sys.executable} -m geoshade.cli.main info --json {f} | head -c 20 >/dev/null; "
           f"{sys.executable} -m geoshade.cli.main --help | head -c 5 >/dev/null")
    res = subprocess.run(["bash", "-o", "pipefail", "-c", cmd], capture_output=True, text=True,
                         timeout=120)
    assert "Traceback" not in res.stderr and "BrokenPipe" not in res.stderr, res.stderr


def test_a_bug_is_reported_as_a_bug(capsys, monkeypatch, tmp_path):
    """An unexpected exception: one line, exit 70, the traceback in a file; --debug prints it."""
    import geoshade.cli.info as info

    def boom(args):
        raise ZeroDivisionError("division by zero in the test")

    monkeypatch.setattr(info, "run", boom)
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)
    rc, _, err = run_cli(capsys, ["info", "anything"])
    lines = err.strip().splitlines()
    assert rc == BUG_EXIT and len(lines) == 1 and "internal error (ZeroDivisionError" in lines[0]
    path = lines[0].rsplit("the traceback is in ", 1)[1]
    assert "Traceback" in open(path).read() and path.startswith(str(tmp_path))
    rc, _, err = run_cli(capsys, ["--debug", "info", "anything"])
    assert rc == BUG_EXIT and "Traceback" in err and "the traceback is above" in err


def test_tally_every_case_clean():
    import sys

    sys.stderr.write(f"{TALLY}\n")   # stdout may be the closed-pipe test's /dev/null
    assert TALLY.tried == 0 or TALLY.clean == TALLY.tried
