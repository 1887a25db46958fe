"""Hostile round 4 (issue 32, item 1): clusters that draw on every install.

``pip install geoshade[distributed]`` brings ``cryptography``, so ``local:N`` starts worker
processes talking TLS; where it is still absent (hidden here in the child by a
``sitecustomize`` that makes ``import cryptography`` fail, as ``tests/test_gl_unavailable.py``
hides PySide6), ``local:N`` says in one warning that its workers are threads of this process,
and ``--distributed`` draws on them, each worker thread with its own OpenGL context current
where it draws: the same picture as one process, pixel for pixel, in both cases.
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np
import pytest

from geoshade import scheduler
from tests.hostile import RESULTS, changed, record, run, snapshot, summary

CLUSTERS = "1 clusters on every install"
distributed = pytest.importorskip("distributed")


def _hide_cryptography(folder) -> dict:
    """The environment of a child in which ``import cryptography`` fails."""
    site = folder / "no_cryptography"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text("import sys\nsys.modules['cryptography'] = None\n")
    return {"PYTHONPATH": os.pathsep.join(p for p in (str(site), os.environ.get("PYTHONPATH"))
                                          if p)}


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    """A 64³ volume store (8 bricks of 32) and a 20×15×6 grid store, made once."""
    from geoshade.compute.grid.synthetic import synthetic_grid
    from geoshade.io.grids.grdecl_writer import write_grdecl

    d = tmp_path_factory.mktemp("clusters")
    z, y, x = np.mgrid[:64, :64, :64]
    vol = ((np.sin(x / 5) + np.cos(y / 7) + np.sin(z / 4)) * 60 + 128).clip(0, 255)
    np.save(d / "w.npy", vol.astype("u1"))
    write_grdecl(synthetic_grid(20, 15, 6, seed=1), d / "g.grdecl")
    for part, src, out in (("core", "w.npy", "w.zarr"), ("grid", "g.grdecl", "g.zarr")):
        r = run(["geoshade", part, "ingest", src, "-o", out], d, timeout=300)
        assert r.rc == 0, r.err
    return d


def _png(path) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(path))


RENDERS = {"core": ["core", "render", "w.zarr", "--bricks", "32", "--select", "100", "255"],
           "grid": ["grid", "render", "g.zarr", "--property", "PORO"]}


@pytest.mark.gl
@pytest.mark.parametrize("part", sorted(RENDERS))
@pytest.mark.parametrize("install", ["with cryptography", "without cryptography"])
def test_distributed_draws_the_one_process_picture(stores, part, install):
    """``--scheduler local:2 --distributed`` on processes (TLS) and, without ``cryptography``,
    on threads: exit 0, the single-process picture exactly, and one warning line only where
    the workers are threads."""
    d = stores
    env = None
    if install == "with cryptography":
        pytest.importorskip("cryptography")
    else:
        env = _hide_cryptography(d)
    size = ["--size", "320x240"]
    one = run(["geoshade", *RENDERS[part], "-o", f"{part}-one.png", *size], d, timeout=300)
    assert one.rc == 0, one.err
    before = snapshot(d)
    out = f"{part}-{install.split()[0]}.png"
    r = run(["geoshade", *RENDERS[part], "-o", out, *size, "--scheduler", "local:2",
             "--distributed", "--worker-timeout", "60"], d, timeout=400, env=env)
    threads = [ln for ln in r.lines if "workers are threads of this process" in ln]
    noise = [ln for ln in r.lines if not ln.startswith("geoshade: warning:")]
    why = "" if r.rc == 0 else f"exit {r.rc}: {r.lines[-1:]}"
    why = why or ("" if not noise and "Traceback" not in r.err else f"stderr: {noise[:2]!r}")
    if install == "without cryptography":
        why = why or ("" if len(threads) == 1 and "pip install 'geoshade[distributed]'"
                      in threads[0] else f"{len(threads)} lines say the workers are threads")
    else:
        why = why or ("" if not threads else "threads said with cryptography present")
    why = why or ("" if "2 workers" in r.out else f"not drawn on 2 workers: {r.out!r}")
    why = why or ", ".join(changed(before, snapshot(d), outputs=[d / out]))
    if not why:
        diff = np.abs(_png(d / out).astype(int) - _png(d / f"{part}-one.png")).max()
        why = "" if diff == 0 else f"differs from one process's picture by up to {diff}"
    record(CLUSTERS, f"{part} render local:2 --distributed, {install}", why, r)


def test_local_cluster_without_cryptography_says_so(monkeypatch):
    """In process: with ``cryptography`` hidden, ``local:1`` is one warning and a cluster of
    threads (in-process transport) that works; with it, no warning."""
    monkeypatch.setitem(sys.modules, "cryptography", None)
    for key in [k for k in sys.modules if k.startswith("cryptography.")]:
        monkeypatch.setitem(sys.modules, key, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        client, owned = scheduler.client_for("local:1")
    try:
        texts = [str(w.message) for w in caught if "threads of this process" in str(w.message)]
        why = "" if len(texts) == 1 and "\n" not in texts[0] and "local:1" in texts[0] \
            else f"{len(texts)} warnings: {texts!r}"
        address = client.scheduler.address
        why = why or ("" if address.startswith("inproc://") else f"address {address}")
        why = why or ("" if client.submit(sum, [1, 2]).result(timeout=30) == 3
                      else "the threads' cluster does not compute")
    finally:
        client.close()
    why = why or ("" if owned else "the cluster is not owned by its client")
    record(CLUSTERS, "local:1 without cryptography: one warning, threads (in process)", why)


def test_the_distributed_extra_brings_cryptography():
    import tomllib
    from pathlib import Path

    meta = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    extra = meta["project"]["optional-dependencies"]["distributed"]
    why = "" if any(r.startswith("cryptography") for r in extra) else f"distributed = {extra}"
    record(CLUSTERS, "pip install geoshade[distributed] brings cryptography", why)


def test_zz_counts():
    if CLUSTERS in RESULTS:
        print(summary(CLUSTERS))
        assert all(ok for _, ok, _ in RESULTS[CLUSTERS]), summary(CLUSTERS)
