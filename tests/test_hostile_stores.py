"""Stores you cannot be lied to by (issue 32, item 4).

A grid store's derived records — colour-scale summaries, code tables, the active count, the
index's faces and per-chunk statistics, the coarse level — are bound to the arrays they describe
(:mod:`geoshade.io.stores.binding`). Each attack tampers with a copy of a store geoshade wrote:

- copied from another store of the same size, edited, or edited and sealed again (a forger who
  knows the algorithm): the record is not used, one warning line says why, and the picture is
  the pristine store's, pixel for pixel (numpy compares the PNGs), or the value is the one
  numpy computes from the arrays;
- malformed attributes: one error line naming the store and the attribute, exit 2;
- two writers of one store (ingest, ``--index-only``, ``--coarse``): the second is refused in
  one line (exit 75);
and nothing outside the outputs changes (SHA-256 of every file).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest
from PIL import Image

from tests.hostile import RESULTS, changed, one_error_line, record, run, snapshot, summary

BOUND, MALFORMED, WRITERS = ("7 stores bound to their data", "8 store attributes of the wrong "
                             "type", "9 one writer per store")
DIMS, CHUNKS = (12, 10, 6), (6, 5, 3)   # 2×2×2 chunks: each touches the grid's boundary


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    """Stores ``a.zarr`` and ``b.zarr`` of the same size and other values, each with its index
    and a coarse level, and a's case as GRDECL."""
    from geoshade.compute.grid.index_faces import store_index
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.grid.lod import write_coarse_level
    from geoshade.io.grids.grdecl_writer import write_grdecl
    from geoshade.io.stores.grid_store import ModelSource, write_grid_store

    d = tmp_path_factory.mktemp("stores")
    for name, seed in (("a", 1), ("b", 2)):
        g = synthetic_grid(*DIMS, seed=seed, steps=2, inactive_fraction=0.1)
        write_grid_store(ModelSource(g), d / f"{name}.zarr", CHUNKS, index=store_index)
        write_coarse_level(d / f"{name}.zarr", 2)
        if name == "a":
            write_grdecl(g, d / "a.grdecl")
    return d


def _copy(stores, tmp_path, name="t.zarr"):
    """A copy of ``a.zarr`` named ``name`` in ``tmp_path``, beside a's case and ``b.zarr``."""
    shutil.copytree(stores / "a.zarr", tmp_path / name)
    for other in ("a.grdecl", "b.zarr"):
        if not (tmp_path / other).exists():
            (shutil.copytree if other.endswith(".zarr") else shutil.copy)(stores / other,
                                                                         tmp_path / other)
    return tmp_path / name


def _meta(p):
    return json.loads((p / "zarr.json").read_text())


def _put(p, meta):
    (p / "zarr.json").write_text(json.dumps(meta))


def _open(path):
    from geoshade.io.stores.grid_store import open_grid_store

    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        g = open_grid_store(path)
    return g, [str(w.message) for w in got]


def _reseal(t):
    """Seal the store's root attributes again for its arrays, as a forger who knows the
    algorithm would (binding.py is public)."""
    from geoshade.io.stores.grid_attrs import sealed

    g, _ = _open(t)
    m = _meta(t)
    m["attributes"] = sealed(m["attributes"], g.meta["digest"])
    _put(t, m)


def _forge_index_array(t, name, change, reseal=True):
    """Change an index array, record its CRC-32 and (``reseal``) seal the record again."""
    import zarr

    from geoshade.io.stores.binding import seal
    from geoshade.io.stores.grid_index import ATTR, _crc

    arr = zarr.open_group(str(t / "index"), mode="r+")[name]
    a = change(np.asarray(arr[...]))
    arr[...] = a
    m = _meta(t)
    gi = m["attributes"][ATTR]
    gi["crc32"][name] = [_crc(r) for r in a] if name.startswith("values/") else _crc(a)
    if reseal:
        gi["seal"] = seal(gi["digest"], ATTR, {k: v for k, v in gi.items() if k != "seal"})
    _put(t, m)


# --------------------------------------------------------------------------------------------
# records bound to the arrays: the pictures
# --------------------------------------------------------------------------------------------
def _forge_summary(t):
    m = _meta(t)
    s = m["attributes"]["summaries"]["props/PORO"]
    s[1] = s[0] + (s[1] - s[0]) * 0.2     # the colour range squeezed: a wrong picture
    _put(t, m)


def _forge_codes(t):
    m = _meta(t)
    m["attributes"]["distinct_codes"]["props/FIPNUM"] = [7, 8, 9]
    _put(t, m)


def _forge_stats(t):
    def lie(a):
        a[..., 0], a[..., 1] = -1.0, -0.5   # "no cell above 0 anywhere"
        return a

    _forge_index_array(t, "stats/props/PORO", lie, reseal=False)


def _copy_index(t):
    other = t.parent / "b.zarr"
    shutil.rmtree(t / "index")
    shutil.copytree(other / "index", t / "index")
    m = _meta(t)
    m["attributes"]["grid_index"] = _meta(other)["attributes"]["grid_index"]
    _put(t, m)


def _copy_lod(t):
    shutil.rmtree(t / "lod")
    shutil.copytree(t.parent / "b.zarr" / "lod", t / "lod")


PICTURES = [
    ("forged summary", _forge_summary, ["--property", "PORO"], "summaries"),
    ("forged code table", _forge_codes, ["--property", "FIPNUM"], "code tables"),
    ("forged per-chunk statistics (filter: every cell matches)", _forge_stats,
     ["--property", "PORO", "--filter", "PORO > 0"], "index is not used"),
    ("index copied from a store of the same size", _copy_index, ["--property", "PORO"],
     "made for other arrays"),
    ("coarse level copied from another grid", _copy_lod, ["--property", "PORO",
                                                          "--progressive"],
     "coarse level is not used"),
]


def _render(folder, store, extra):
    out = folder / f"{store}.png"
    r = run(["geoshade", "grid", "render", store, "-o", out.name, "--size", "160x120",
             "--no-annotations", *extra], folder, timeout=300)
    img = np.asarray(Image.open(out)) if out.exists() else None
    out.unlink(missing_ok=True)
    return r, img


@pytest.fixture(scope="module")
def pristine(stores, tmp_path_factory):
    """The pristine store's picture with the options ``extra`` (a copy of ``a.zarr`` beside
    the other stores), drawn once per options: ``pristine(extra)``."""
    folder, drawn = None, {}

    def picture(extra):
        nonlocal folder
        if folder is None:
            folder = tmp_path_factory.mktemp("pristine")
            _copy(stores, folder, "p.zarr")
        if tuple(extra) not in drawn:
            drawn[tuple(extra)] = _render(folder, "p.zarr", extra)[1]
        return drawn[tuple(extra)]
    return picture


@pytest.mark.gl
@pytest.mark.parametrize(("name", "tamper", "extra", "needle"), PICTURES,
                         ids=[p[0] for p in PICTURES])
def test_tampered_records_draw_the_true_picture(stores, pristine, tmp_path, name, tamper, extra,
                                                needle):
    """Exit 0, one warning line, and the pristine store's picture."""
    t = _copy(stores, tmp_path)
    tamper(t)
    want = pristine(extra)
    before = snapshot(tmp_path)
    r, got = _render(tmp_path, "t.zarr", extra)
    warns = [ln for ln in r.lines if ln.startswith("geoshade: warning:")]
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-2:]!r}"
    why = why or ("" if len(warns) == 1 and needle in warns[0] and len(r.lines) == 1
                  else f"stderr {r.lines!r}")
    why = why or ("" if got is not None and np.array_equal(got, want) else "another picture")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(BOUND, name, why, r)


# --------------------------------------------------------------------------------------------
# the same, in process: resealed forgeries caught by the sample
# --------------------------------------------------------------------------------------------
def test_resealed_summary_and_codes_are_caught_by_the_sample(stores, tmp_path):
    from geoshade.compute.grid.cell_values import summarise
    from geoshade.grid.lazy import lazy_codes, stored_codes, stored_summary

    t = _copy(stores, tmp_path)
    _forge_summary(t)
    _forge_codes(t)
    _reseal(t)
    g, said = _open(t)
    assert not said and g.meta["bound"]["derived"]          # the seals hold now...
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        poro, codes = stored_summary(g, g.properties["PORO"]), stored_codes(
            g, g.properties["FIPNUM"])
    said = " | ".join(str(w.message) for w in got)
    act = np.asarray(g.actnum) != 0
    why = "" if poro is None and codes is None else "a forged record was used"
    why = why or ("" if "summary it keeps of props/PORO does not match" in said and
                  "code table it keeps of props/FIPNUM" in said else f"said {said!r}")
    true = summarise(np.asarray(g.properties["PORO"]), act)
    why = why or ("" if np.array_equal(lazy_codes(g, g.properties["FIPNUM"]),
                                       np.unique(np.asarray(g.properties["FIPNUM"])[act]))
                  and true.hi > 0.2 else "the values computed differ from numpy's")
    record(BOUND, "summary and code table forged and sealed again (sampled)", why)


def test_resealed_statistics_and_faces_are_caught_by_the_sample(stores, tmp_path):
    from geoshade.compute.grid.index_faces import sample_faces
    from geoshade.io.stores.grid_index import GridIndex, open_index

    t = _copy(stores, tmp_path)

    def lie(a):
        a[..., 0], a[..., 1] = -1.0, -0.5
        return a

    _forge_index_array(t, "stats/props/PORO", lie)
    g, _ = _open(t)
    stats = open_index(g, sample_faces)
    t2 = _copy(stores, tmp_path, "f.zarr")
    _forge_index_array(t2, "faces/flags", lambda a: a ^ np.uint8(1))   # faults flipped
    g2, _ = _open(t2)
    faces, without = open_index(g2, sample_faces), open_index(g2)
    why = "" if isinstance(stats, str) and "statistics of props/PORO differ" in stats else \
        f"stats: {stats!r}"
    why = why or ("" if isinstance(faces, str) and "its faces are not those" in faces
                  else f"faces: {faces!r}")
    why = why or ("" if isinstance(without, GridIndex) else "the faces needed the sample")
    record(BOUND, "index statistics and faces forged and sealed again (sampled)", why)


def test_copies_and_stale_records_in_process(stores, tmp_path):
    """An index or coarse level from another store, arrays swapped under their records, a
    store without seals, a forged active count: not used, one line each."""
    from geoshade.grid.lod import coarse_level
    from geoshade.io.stores.grid_index import open_index

    t = _copy(stores, tmp_path)
    _copy_index(t)
    _copy_lod(t)
    g, said = _open(t)
    idx, (level, note) = open_index(g), coarse_level(g)
    why = "" if isinstance(idx, str) and "made for other arrays" in idx else f"index {idx!r}"
    why = why or ("" if level is None and "not made from the store's arrays" in note
                  else f"level {note!r}")
    s = _copy(stores, tmp_path, "s.zarr")   # an array swapped for the other store's
    shutil.rmtree(s / "props" / "PORO")
    shutil.copytree(stores / "b.zarr" / "props" / "PORO", s / "props" / "PORO")
    g, said = _open(s)
    why = why or ("" if len(said) == 1 and "arrays are not those it was written with" in said[0]
                  and not g.meta["summaries"] and isinstance(open_index(g), str)
                  else f"swapped: {said!r}")
    o = _copy(stores, tmp_path, "o.zarr")   # no seals (an older store): nothing derived used
    m = _meta(o)
    del m["attributes"]["grid_store"]["seals"]
    _put(o, m)
    g, said = _open(o)
    why = why or ("" if len(said) == 1 and "older geoshade" in said[0] and
                  not g.meta["distinct_codes"] else f"older: {said!r}")
    n = _copy(stores, tmp_path, "n.zarr")   # a forged active count: counted from ACTNUM
    m = _meta(n)
    m["attributes"]["grid_store"]["nactive"] = 3
    _put(n, m)
    g, said = _open(n)
    true = int(np.count_nonzero(np.asarray(g.actnum)))
    why = why or ("" if g.nactive == true != 3 and len(said) == 1 else f"nactive {g.nactive}")
    record(BOUND, "copied index and level, swapped array, no seals, forged count", why)


# --------------------------------------------------------------------------------------------
# malformed attributes: one line naming the store and the attribute
# --------------------------------------------------------------------------------------------
def _attr(key, value):
    def f(t):
        m = _meta(t)
        m["attributes"][key] = value
        _put(t, m)
    return f


def _gs(key, value):
    def f(t):
        m = _meta(t)
        m["attributes"]["grid_store"][key] = value
        _put(t, m)
    return f


MALFORMED_CASES = [
    ("faults", 5, "faults"), ("faults", [{"name": "F", "faces": [[1, 2]]}], "faults"),
    ("faults", [{"name": "F", "faces": [[999, 0, 0, 0]]}], "faults"),
    ("faults", [{"nom": 1}], "faults"), ("faults", [{"name": "F", "faces": [["a"] * 4]}],
                                         "faults"),
    ("meta", [1, 2], "meta"), ("meta", "x", "meta"), ("meta", {"codes": {"F": {"x": 1}}}, "meta"),
    ("mapaxes", "abc", "mapaxes"), ("mapaxes", [1, 2], "mapaxes"),
    ("mapaxes", [1, 2, 3, 4, 5, "x"], "mapaxes"), ("units", {"a": 1}, "units"),
    ("step_dates", 5, "step_dates"), ("step_seqnum", "x", "step_seqnum"),
    ("summaries", "x", "summaries"), ("distinct_codes", [1], "distinct_codes"),
    ("grid_store.nactive", "x", "nactive"), ("grid_store.nactive", -5, "nactive"),
    ("grid_store.nactive", [1], "nactive"), ("grid_store.properties", "PORO", "grid_store"),
    ("grid_store.chunks", [0, 0, 0], "grid_store"), ("grid_store.chunks", [3, 3, 3],
                                                      "grid_store"),
    ("grid_store.dims", "x", "grid_store"),
]


@pytest.mark.parametrize(("key", "value", "needle"), MALFORMED_CASES,
                         ids=[f"{k}={json.dumps(v)[:30]}" for k, v, _ in MALFORMED_CASES])
def test_malformed_attribute_is_one_line(stores, tmp_path, key, value, needle):
    t = _copy(stores, tmp_path)
    (_gs(key.split(".")[1], value) if key.startswith("grid_store.") else _attr(key, value))(t)
    before = snapshot(tmp_path)
    r = run(["geoshade", "info", "t.zarr"], tmp_path, timeout=120)
    why = one_error_line(r, "t.zarr", needle) or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(MALFORMED, f"info: {key} = {json.dumps(value)[:40]}", why, r)


@pytest.mark.parametrize("where", ["store", "level"])
def test_a_fifo_for_zarr_json_is_one_line(stores, tmp_path, where):
    """A FIFO named ``zarr.json`` (the store's, or its coarse level's) never blocks a reader:
    ``info`` is one line; the View draws without the level and says so."""
    from geoshade.grid.lod import coarse_level

    t = _copy(stores, tmp_path)
    meta = t / "zarr.json" if where == "store" else t / "lod" / "zarr.json"
    meta.unlink()
    os.mkfifo(meta)
    if where == "store":
        before = snapshot(tmp_path)
        r = run(["geoshade", "info", "t.zarr"], tmp_path, timeout=60)
        why = one_error_line(r, "zarr.json", "not a regular file") or (
            "" if r.rc == 2 else f"exit {r.rc}")
        why = why or ", ".join(changed(before, snapshot(tmp_path)))
        record(MALFORMED, "a FIFO for the store's zarr.json: info", why, r)
        return
    g, _ = _open(t)
    level, note = coarse_level(g)
    why = "" if level is None and "coarse level" in note else f"level {level!r}: {note!r}"
    record(MALFORMED, "a FIFO for the coarse level's zarr.json (in process)", why)


@pytest.mark.gl
@pytest.mark.parametrize(("key", "value", "needle"), [("faults", 5, "faults"),
                                                      ("grid_store.nactive", "x", "nactive")])
def test_malformed_attribute_render_is_one_line(stores, tmp_path, key, value, needle):
    t = _copy(stores, tmp_path)
    (_gs(key.split(".")[1], value) if key.startswith("grid_store.") else _attr(key, value))(t)
    before = snapshot(tmp_path)
    r = run(["geoshade", "grid", "render", "t.zarr", "-o", "x.png", "--size", "64x48"],
            tmp_path, timeout=300)
    why = one_error_line(r, "t.zarr", needle) or ("" if r.rc == 2 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, snapshot(tmp_path)))
    record(MALFORMED, f"grid render: {key} = {json.dumps(value)}", why, r)


@pytest.mark.parametrize("factor", ["x", 0, -1, 3, 1e9, None, True])
def test_malformed_level_factor_is_one_line(stores, tmp_path, factor):
    """A level's ``factor`` of the wrong type or value: the level is not used (one line from
    the View), or one error line from the reader; never an internal error."""
    from geoshade.errors import InputError
    from geoshade.grid.lod import coarse_level
    from geoshade.io.stores.grid_lod import read_coarse_level

    t = _copy(stores, tmp_path)
    m = _meta(t / "lod")
    m["attributes"]["meta"]["lod"]["factor"] = factor
    _put(t / "lod", m)
    g, _ = _open(t)
    level, note = coarse_level(g)
    try:
        read_coarse_level(t)
        err = ""
    except InputError as e:
        err = str(e)
    why = "" if level is None and "lod" in note and "factor" in err + note else \
        f"level {level!r}, note {note!r}"
    why = why or ("" if "\n" not in note and "t.zarr/lod" in err else f"error {err!r}")
    record(MALFORMED, f"coarse level factor = {json.dumps(factor)}", why)


# --------------------------------------------------------------------------------------------
# one writer per store
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv", [["grid", "ingest", "--index-only", "t.zarr"],
                                  ["grid", "ingest", "--coarse", "2", "t.zarr"],
                                  ["grid", "ingest", "a.grdecl", "-o", "t.zarr", "--overwrite"],
                                  ["grid", "ingest", "a.grdecl", "-o", "t.zarr", "--overwrite",
                                   "--coarse", "2"]],
                         ids=["--index-only", "--coarse", "ingest --overwrite",
                              "ingest --coarse"])
def test_second_writer_is_refused(stores, tmp_path, argv):
    """Another writer holds the store's lock (this process, as an ingest would): the second
    is one line, exit 75, and changes nothing."""
    from geoshade.io.stores.ingest_lock import IngestLock

    t = _copy(stores, tmp_path)
    with IngestLock(t, task="grid ingest --index-only"):
        before = snapshot(tmp_path)
        r = run(["geoshade", *argv], tmp_path, timeout=300)
        after = snapshot(tmp_path)
    why = one_error_line(r, "t.zarr", "another ingest is writing") or (
        "" if r.rc == 75 else f"exit {r.rc}")
    why = why or ", ".join(changed(before, after))
    record(WRITERS, f"{' '.join(argv[1:])} while another writes", why, r)


def test_two_index_only_runs_at_once(stores, tmp_path):
    """Two ``--index-only`` started together: each ends in exit 0 or in the one busy line, and
    the store's index is whole and used afterwards (was: both exit 0, the index lost)."""
    from geoshade.compute.grid.index_faces import sample_faces
    from geoshade.io.stores.grid_index import GridIndex, open_index

    t = _copy(stores, tmp_path)
    argv = [sys.executable, "-m", "geoshade.cli.main", "grid", "ingest", "--index-only", str(t)]
    first = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    while not (tmp_path / "t.zarr.lock").exists() and first.poll() is None \
            and time.monotonic() - t0 < 120:
        time.sleep(0.005)
    second = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    _, err = first.communicate(timeout=300)
    lines = [ln for ln in (err + second.stderr).splitlines() if ln.strip()]
    why = "" if first.returncode == 0 and second.returncode in (0, 75) else \
        f"exits {first.returncode}, {second.returncode}: {lines[-2:]!r}"
    why = why or ("" if all(ln.startswith("geoshade: error:") and "another ingest" in ln
                            for ln in lines) else f"stderr {lines!r}")
    g, _ = _open(t)
    why = why or ("" if isinstance(open_index(g, sample_faces), GridIndex) else "index lost")
    record(WRITERS, f"two --index-only at once (second exit {second.returncode})", why)


def test_zz_counts():
    """The tried / clean table of this file's classes (``pytest -s`` prints it)."""
    for cls in (BOUND, MALFORMED, WRITERS):
        if cls in RESULTS:
            print(summary(cls))
            assert all(ok for _, ok, _ in RESULTS[cls]), summary(cls)
