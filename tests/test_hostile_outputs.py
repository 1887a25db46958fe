"""Outputs that never delete what they do not own (issue 32, item 3).

``--overwrite`` replaces only what geoshade wrote: a store it recognises as its own (its
``zarr.json`` marker, holding nothing else) or a file. Each case runs the real CLI in a child
process (:mod:`tests.hostile`) in a sandbox and asserts the one clean line before any work and
that no file anywhere in the sandbox changed, appeared or vanished (SHA-256 of every file, the
target of every link); the accepted cases assert the new store and that nothing else changed.
"""

from __future__ import annotations

import json
import os
import shutil
import stat

import numpy as np
import pytest

from tests.hostile import RESULTS, changed, one_error_line, record, run, snapshot, summary

OUTPUTS = "6 outputs that never delete what they do not own"
SECRET = b"precious: must never be deleted\n"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A GRDECL case, a volume and a grid store geoshade wrote, made once."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl
    from geoshade.io.stores.grid_store import ModelSource, write_grid_store

    d = tmp_path_factory.mktemp("outputs-inputs")
    write_grdecl(synthetic_grid(5, 4, 3, seed=1, steps=0), d / "g.grdecl")
    np.save(d / "v.npy", np.random.default_rng(0).integers(0, 255, (8, 8, 8)).astype("u1"))
    write_grid_store(ModelSource(synthetic_grid(5, 4, 3, seed=2, steps=0)), d / "own.zarr",
                     (4, 4, 2))
    return d


@pytest.fixture
def sandbox(tmp_path, inputs):
    """``box/here`` (the working folder: the inputs and a note), ``box/outside`` (a file that
    must survive)."""
    here = tmp_path / "box" / "here"
    here.mkdir(parents=True)
    for name in ("g.grdecl", "v.npy"):
        shutil.copy(inputs / name, here)
    (here / "notes.txt").write_bytes(SECRET)
    (tmp_path / "box" / "outside").mkdir()
    (tmp_path / "box" / "outside" / "keep.txt").write_bytes(SECRET)
    return here


def _own_store(inputs, where):
    shutil.copytree(inputs / "own.zarr", where)


def _foreign_zarr(where):
    import zarr

    z = zarr.open_array(str(where), mode="w", shape=(4,), dtype="u1")
    z[:] = 1


def _device(where):
    try:
        os.mknod(where, 0o600 | stat.S_IFCHR, os.makedev(1, 3))   # a /dev/null twin
    except PermissionError:
        pytest.skip("making a device node needs root")


# (case, setup(here, inputs) -> (-o value, cwd relative to here), needles)
REFUSED = [
    ("a folder holding a user's file", lambda h, i: (
        (h / "proj").mkdir(), (h / "proj" / "report.docx").write_bytes(SECRET), "proj")[-1],
     ".", ("proj", "did not write", "report.docx")),
    ("the folder holding the input", lambda h, i: "in", ".", ("in", "holding the input")),
    (". (the working folder)", lambda h, i: ".", ".", ("working folder",)),
    ("../here from inside it", lambda h, i: "../here", ".", ("working folder",)),
    (".. from a subfolder", lambda h, i: ((h / "sub").mkdir(), "..")[-1], "sub",
     ("holding the working folder",)),
    ("a device node", lambda h, i: (_device(h / "dev"), "dev")[-1], ".", ("a device",)),
    ("a FIFO", lambda h, i: (os.mkfifo(h / "fifo"), "fifo")[-1], ".", ("a FIFO",)),
    ("a link to a folder outside", lambda h, i: (
        os.symlink(h.parent / "outside", h / "lnk"), "lnk")[-1], ".",
     ("symbolic link", "outside")),
    ("a link to a store of geoshade's", lambda h, i: (
        _own_store(i, h.parent / "outside" / "s.zarr"),
        os.symlink(h.parent / "outside" / "s.zarr", h / "s.zarr"), "s.zarr")[-1], ".",
     ("symbolic link",)),
    ("a zarr store geoshade did not write", lambda h, i: (_foreign_zarr(h / "f.zarr"),
                                                          "f.zarr")[-1], ".",
     ("f.zarr", "did not write")),
    ("its own store holding a user's file", lambda h, i: (
        _own_store(i, h / "s.zarr"), (h / "s.zarr" / "thesis.tex").write_bytes(SECRET),
        "s.zarr")[-1], ".", ("s.zarr", "thesis.tex")),
]


@pytest.mark.parametrize("part", ["grid", "core"])
@pytest.mark.parametrize(("name", "setup", "cwd", "needles"), REFUSED,
                         ids=[c[0] for c in REFUSED])
@pytest.mark.parametrize("overwrite", [True, False], ids=["--overwrite", "plain"])
def test_overwrite_refuses_what_it_does_not_own(sandbox, inputs, part, name, setup, cwd,
                                                needles, overwrite):
    here = sandbox
    src = "g.grdecl" if part == "grid" else "v.npy"
    out = setup(here, inputs)
    if name == "the folder holding the input":
        (here / "in").mkdir()
        shutil.copy(here / src, here / "in" / src)
        src = f"in/{src}"
    work = (here / cwd).resolve()
    if cwd != ".":
        src = os.path.relpath(here / src, work)
    box = here.parent
    before = snapshot(box)
    r = run(["geoshade", part, "ingest", src, "-o", out, *(["--overwrite"] if overwrite else [])],
            work, timeout=300)
    why = one_error_line(r, *needles) or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(box)))
    why = why or ("" if r.maxrss_mb < 1500 else f"peak {r.maxrss_mb:.0f} MB")
    record(OUTPUTS, f"{part} ingest -o {name}{' --overwrite' if overwrite else ''}", why, r)


@pytest.mark.parametrize("part", ["grid", "core"])
@pytest.mark.parametrize("what", ["its own store", "a file", "an empty folder"])
def test_overwrite_replaces_what_it_owns(sandbox, inputs, part, what):
    """A store geoshade wrote, a file and an empty folder are replaced by the new store;
    nothing else changes."""
    here = sandbox
    if what == "its own store":
        _own_store(inputs, here / "s.zarr")
    elif what == "a file":
        (here / "s.zarr").write_bytes(b"old")
    else:
        (here / "s.zarr").mkdir()
    src = "g.grdecl" if part == "grid" else "v.npy"
    before = snapshot(here.parent)
    r = run(["geoshade", part, "ingest", src, "-o", "s.zarr", "--overwrite"], here, timeout=300)
    attrs = json.loads((here / "s.zarr" / "zarr.json").read_text())["attributes"] \
        if (here / "s.zarr" / "zarr.json").is_file() else {}
    marker = "grid_store" if part == "grid" else "ingest"
    why = "" if r.rc == 0 and marker in attrs else f"exit {r.rc}: {r.lines[-2:]!r}"
    why = why or ", ".join(changed(before, snapshot(here.parent), outputs=[here / "s.zarr"]))
    why = why or ("" if not [p for p in here.iterdir() if p.name.startswith("s.zarr.")]
                  else "a lock or partial store was left")
    record(OUTPUTS, f"{part} ingest --overwrite replaces {what}", why, r)


def test_the_input_itself_is_refused(sandbox):
    """``-o`` naming the input (a file) or one of its case's files is refused."""
    here = sandbox
    before = snapshot(here.parent)
    r = run(["geoshade", "core", "ingest", "v.npy", "-o", "v.npy", "--overwrite"], here)
    why = one_error_line(r, "v.npy") or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(here.parent)))
    record(OUTPUTS, "core ingest -o the input --overwrite", why, r)


def test_check_replace_and_publish_in_process(tmp_path, monkeypatch):
    """The library refuses too: ``write_zarr`` over a user's folder, the one atomic publish over
    a folder it did not write (the last guard), ``write_grid_store`` over a link."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.errors import InputError
    from geoshade.io.output import check_replace, own_store, publish
    from geoshade.io.stores.grid_store import ModelSource, write_grid_store
    from geoshade.io.stores.zarr_io import write_zarr
    from geoshade.models import VoxelVolume

    user = tmp_path / "user"
    user.mkdir()
    (user / "keep.txt").write_bytes(SECRET)
    vol = VoxelVolume(np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(InputError, match="did not write"):
        write_zarr(vol, user, overwrite=True)
    staged = tmp_path / ".x.new"
    staged.mkdir()
    with pytest.raises(InputError, match="did not write"):
        publish(staged, user)
    os.symlink(user, tmp_path / "lnk.zarr")
    with pytest.raises(InputError, match="symbolic link"):
        write_grid_store(ModelSource(synthetic_grid(3, 3, 2)), tmp_path / "lnk.zarr", (2, 2, 2),
                         overwrite=True)
    assert (user / "keep.txt").read_bytes() == SECRET and sorted(os.listdir(user)) == ["keep.txt"]
    store = write_zarr(vol, tmp_path / "v.zarr")
    assert own_store(store) and not own_store(user)
    check_replace(store)                              # its own: may be replaced
    write_zarr(vol, store, overwrite=True)
    monkeypatch.chdir(user)
    with pytest.raises(InputError, match="working folder"):
        check_replace(user)
    record(OUTPUTS, "write_zarr, publish, write_grid_store (in process)", "")


def test_zz_counts():
    """The tried / clean table (``pytest -s`` prints it)."""
    if OUTPUTS in RESULTS:
        print(summary(OUTPUTS))
        assert all(ok for _, ok, _ in RESULTS[OUTPUTS]), summary(OUTPUTS)
