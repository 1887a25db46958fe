"""Clean lines everywhere (issue 25, class 5): control characters from files escaped on the
terminal, JSON depth and camera values bounded, a closed or full stdout, repeated warnings
counted, library logs silent, OS errors naming their file, stores without the user's folders,
Ctrl-C during an ingest in one line.
"""

from __future__ import annotations

import json
import os
import pty
import sys
import warnings

import numpy as np
import pytest

from geoshade.errors import InputError
from tests.hostile import (
    RESULTS,
    changed,
    interrupt_when,
    one_error_line,
    record,
    run,
    snapshot,
    summary,
)

LINES = "5 clean lines"
ESC = "\x1b]52;c;cHduZWQ=\x07\x1b[2J\x1b]0;title\x07"  # clipboard write, screen clear, title


@pytest.fixture
def vol(tmp_path):
    np.save(tmp_path / "v.npy", np.random.default_rng(0).integers(0, 255, (12, 12, 12))
            .astype("u1"))
    return tmp_path


def _deck(folder, compdat: int = 0):
    """A deck whose fault and well names carry escape sequences, and ``compdat`` COMPDAT records
    for wells never declared."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    write_grdecl(synthetic_grid(4, 3, 2, seed=1), folder / "g.grdecl")
    recs = "".join(f" 'GHOST{i}' 1 1 1 1 OPEN /\n" for i in range(compdat))
    (folder / "CASE.DATA").write_text(
        "RUNSPEC\nDIMENS\n 4 3 2 /\nGRID\nINCLUDE\n 'g.grdecl' /\n"
        f"FAULTS\n 'F{ESC}' 1 1 1 3 1 2 X /\n/\n"
        f"SCHEDULE\nWELSPECS\n 'W{ESC}' G 2 2 1* OIL /\n/\n"
        f"COMPDAT\n 'W{ESC}' 2 2 1 2 OPEN /\n 'X{ESC}' 2 2 1 2 OPEN /\n{recs}/\n")
    return folder / "CASE.DATA"


def test_control_characters_escaped_on_the_terminal(tmp_path):
    """Fault and well names from a file reach a terminal escaped (stdout on a pty, stderr)."""
    _deck(tmp_path)
    master, slave = pty.openpty()
    try:
        r = run(["geoshade", "info", "CASE.DATA"], tmp_path, stdout=slave, timeout=120)
        os.close(slave)
        shown = b""
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                break
            if not chunk:
                break
            shown += chunk
    finally:
        os.close(master)
    text = shown.decode("utf-8", "replace")
    why = "" if r.rc == 0 and "F\\x1b]52;c;" in text else f"exit {r.rc}: {text[-200:]!r}"
    why = why or ("" if "\x1b" not in text and "\x07" not in text else "escape on the terminal")
    why = why or ("" if "\x1b" not in r.err and "X\\x1b]52" in r.err else
                  f"stderr: {r.err[-300:]!r}")
    record(LINES, "fault/well names with escape sequences", why, r)


def test_progress_bar_keeps_its_own_control_characters():
    """The terminal stream escapes text from files, not the progress bar's carriage returns."""
    import io

    from tqdm import tqdm

    from geoshade.cli.main import _Stream

    buf = io.StringIO()
    stream = _Stream(buf, "<standard error>", True)
    bar = tqdm(total=3, file=stream, leave=False, mininterval=0)
    bar.update(3)
    bar.close()
    stream.write(f"name {ESC}\n")
    text = buf.getvalue()
    why = "" if "\r" in text and "\x1b" not in text and "name \\x1b]52" in text else repr(text)
    record(LINES, "progress bar drawn, file text escaped (in process)", why)


def test_escapes_in_a_file_name_are_escaped(tmp_path):
    r = run(["geoshade", "info", f"a{ESC}.raw"], tmp_path, timeout=60)
    why = one_error_line(r, "a\\x1b]52;c;") or ("" if r.rc == 2 else f"exit {r.rc}")
    record(LINES, "escape sequences in a file name", why, r)


def test_many_alike_warnings_counted_in_one(tmp_path):
    """100,000 COMPDAT records naming undeclared wells: one warning line, not 100,000."""
    _deck(tmp_path, compdat=100_000)
    r = run(["geoshade", "info", "CASE.DATA"], tmp_path, timeout=300)
    compdat = [ln for ln in r.lines if "COMPDAT" in ln]
    why = "" if r.rc == 0 and len(compdat) == 1 and "10000" in compdat[0] and \
        "GHOST7' and " in compdat[0] else f"exit {r.rc}, {len(compdat)} COMPDAT lines: " \
        f"{compdat[:2]!r}"[:300]
    record(LINES, "100,000 COMPDAT warnings", why, r)


def test_cli_counts_alike_warnings(capsys):
    from geoshade.cli.main import _print_warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for i in range(1000):
            warnings.warn(f"f.txt: record {i}: odd value", UserWarning, stacklevel=1)
        warnings.warn("g.txt: something else", UserWarning, stacklevel=1)
    _print_warnings(caught)
    lines = capsys.readouterr().err.splitlines()
    why = "" if len(lines) == 5 and "997 more warnings like these" in lines[3] else \
        f"{len(lines)} lines: {lines[:5]!r}"
    record(LINES, "1000 alike warnings (in process)", why)


DEEP = "[" * 100_000 + "]" * 100_000


def test_deep_json_camera(vol):
    (vol / "cam.json").write_text(DEEP)
    before = snapshot(vol)
    r = run(["geoshade", "core", "render", "v.npy", "-o", "x.png", "--size", "64x48",
             "--select", "0", "100", "--camera", "cam.json"], vol, timeout=200)
    why = one_error_line(r, "cam.json", "nested too deeply") or ("" if r.rc == 2 else
                                                                 f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(vol), ["x.png"]))
    record(LINES, "100,000 nested [ in a camera file", why, r)


def test_deep_json_store(tmp_path):
    d = tmp_path / "deep.zarr"
    d.mkdir()
    (d / "zarr.json").write_text('{"zarr_format": 3, "node_type": "array", "attributes": '
                                 + DEEP + "}")
    r = run(["geoshade", "info", "deep.zarr"], tmp_path, timeout=120)
    why = one_error_line(r, "deep.zarr") or ("" if r.rc == 2 else f"exit {r.rc}")
    record(LINES, "100,000 nested [ in a store's zarr.json", why, r)


def test_deep_json_stack_header(tmp_path):
    from geoshade.io.layers.stackfile import MEMBERS

    header = ('{"format": "geoshade-stacks", "x": ' + DEEP + "}").encode()
    arrays = {m: np.zeros(1, np.int32) for m in MEMBERS}
    arrays["header"] = np.frombuffer(header, np.uint8)
    np.savez(tmp_path / "deep.stacks.npz", **arrays)
    r = run(["geoshade", "info", "deep.stacks.npz"], tmp_path, timeout=120)
    why = one_error_line(r, "deep.stacks.npz", "nested too deeply") or (
        "" if r.rc == 2 else f"exit {r.rc}")
    record(LINES, "100,000 nested [ in a stack model header", why, r)


def _camera(**change) -> dict:
    from geoshade.styles.saved_camera import SavedCamera

    cam = SavedCamera((0.5, 0.5, 0.5), 3.0, 30.0, 20.0, 30.0, False, 1.0, 1.5, 0.9,
                      ((0, 0, 0), (1, 1, 1)), None)
    return {**cam.as_dict(), **change}


CAMERAS = [("fovy 179.99999", {"fovy": 179.99999}, "fovy"), ("fovy 1e300", {"fovy": 1e300},
           "fovy"), ("distance 1e300", {"distance": 1e300}, "distance"),
           ("target 1e12 away", {"target": [1e12, 0, 0]}, "target"),
           ("radius 1e300", {"radius": 1e300, "distance": 1e300}, "radius"),
           ("format version 2", {"geoshade_camera": 2}, "format version 2"),
           ("aspect 1e-300", {"aspect": 1e-300}, "aspect")]


@pytest.mark.parametrize(("name", "change", "needle"), CAMERAS, ids=[c[0] for c in CAMERAS])
def test_camera_values_bounded(name, change, needle):
    from geoshade.styles.saved_camera import SavedCamera

    SavedCamera.from_dict(_camera(), "ok.json")  # the unchanged camera reads
    with pytest.raises(InputError) as info:
        SavedCamera.from_dict(_camera(**change), "cam.json")
    text = str(info.value)
    why = "" if text.startswith("cam.json: ") and needle in text and "\n" not in text else text
    record(LINES, f"camera {name}", why)


def test_camera_out_of_bounds_through_the_cli(vol):
    (vol / "cam.json").write_text(json.dumps(_camera(fovy=179.99999)))
    r = run(["geoshade", "core", "render", "v.npy", "-o", "x.png", "--size", "64x48",
             "--select", "0", "100", "--camera", "cam.json"], vol, timeout=200)
    why = one_error_line(r, "cam.json", "fovy") or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ("" if not (vol / "x.png").exists() else "a picture was drawn")
    record(LINES, "camera fovy 179.99999 (CLI)", why, r)


def test_closed_stdout(vol):
    """``>&-``: the command still does its work and ends quietly (was AttributeError)."""
    r = run(["sh", "-c", f"exec {sys.executable} -m geoshade.cli.main info v.npy >&-"], vol,
            timeout=120)
    why = "" if r.rc == 0 and not r.lines else f"exit {r.rc}: {r.lines[:2]!r}"
    record(LINES, "stdout closed", why, r)


def test_full_stdout(vol):
    with open("/dev/full", "w") as full:
        r = run(["geoshade", "info", "v.npy"], vol, stdout=full, timeout=120)
    why = one_error_line(r, "<standard output>", "no space left on device") or (
        "" if r.rc == 74 else f"exit {r.rc}")
    record(LINES, "stdout full (/dev/full)", why, r)


def test_os_error_names_the_output(tmp_path):
    from geoshade.cli.main import _os_error_line
    from geoshade.io.output import _write_named

    with pytest.raises(OSError) as info:
        _write_named(lambda: open("/dev/full", "wb"), b"x" * 100, tmp_path / "out.png")
    line = _os_error_line(info.value)
    why = "" if line == f"{tmp_path / 'out.png'}: no space left on device" else line
    record(LINES, "full disk names the output (in process)", why)


def test_library_logs_silenced():
    import logging

    from geoshade.cli.main import _quiet_libraries

    names = ("distributed", "asyncio", "tornado")
    saved = {n: logging.getLogger(n).level for n in names}
    try:
        _quiet_libraries(debug=False)
        loud = [n for n in names if logging.getLogger(n).isEnabledFor(logging.CRITICAL)]
    finally:
        for n, level in saved.items():
            logging.getLogger(n).setLevel(level)
    record(LINES, "distributed/asyncio logs silent (in process)", ", ".join(loud))


def test_store_keeps_the_input_name_not_its_folders(vol):
    r = run(["geoshade", "core", "ingest", "v.npy", "-o", "out.zarr"], vol, timeout=120)
    texts = "".join(p.read_text() for p in (vol / "out.zarr").rglob("zarr.json"))
    why = "" if r.rc == 0 and '"source": "v.npy"' in texts else f"exit {r.rc}: no source"
    why = why or ("" if str(vol) not in texts and os.path.expanduser("~") not in texts else
                  "the store records the input's folders")
    record(LINES, "store records the input's name only", why, r)


@pytest.mark.parametrize("where", ["threads", "local:1"])
def test_ctrl_c_during_an_ingest_is_one_line(tmp_path, where):
    """SIGINT once the partial store exists: 'geoshade: interrupted' and what is kept, nothing
    else (no asyncio traceback, no "Task was destroyed" from a cluster); the same ingest again
    finishes the store."""
    if where != "threads":
        pytest.importorskip("distributed")
    np.random.default_rng(2).integers(0, 60000, (160, 160, 160)).astype("u2").tofile(
        tmp_path / "big.raw")
    argv = ["geoshade", "core", "ingest", "big.raw", "--shape", "160", "160", "160", "--dtype",
            "uint16", "--chunks", "4", "32", "32", "--levels", "3", "-o", "out.zarr",
            *(["--scheduler", where] if where != "threads" else [])]
    r = run(argv, tmp_path, timeout=300, on_start=interrupt_when(tmp_path / "out.zarr.partial"))
    if r.rc == 0:
        pytest.skip("the ingest ended before the interrupt arrived")
    why = "" if r.rc == 130 and len(r.lines) == 1 and r.lines[0].startswith(
        "geoshade: interrupted; out.zarr.partial keeps the finished slabs") else \
        f"exit {r.rc}: {r.lines[:3]!r} ({len(r.lines)} lines)"
    again = run(argv, tmp_path, timeout=300)
    why = why or ("" if again.rc == 0 and (tmp_path / "out.zarr").is_dir() else
                  f"the rerun: exit {again.rc} {again.lines[-1:]!r}")
    record(LINES, f"Ctrl-C during an ingest ({where})", why, r)


def test_zz_counts():
    if LINES in RESULTS:
        print(summary(LINES))
        assert all(ok for _, ok, _ in RESULTS[LINES]), summary(LINES)
