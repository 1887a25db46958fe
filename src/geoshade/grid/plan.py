"""GPU memory of a grid before anything is allocated: each approach's bytes, and whether they fit;
the memory plan's routes of a grid before it is loaded.

:func:`gpu_plans` counts the visible faces on the CPU (:func:`geoshade.compute.grid.faces.
visible_faces`, the numba kernel at scale) and sizes every GPU object of every approach with
:func:`geoshade.render.visuals.grid.layout.gpu_plan` — the function whose sizes the renderer
allocates (a test checks ``GpuCache.breakdown() == plan``).  ``geoshade info CASE --gpu`` prints
it; ``GridView`` refuses, before its first GPU object, a plan larger than ``gpu_memory``.

The device's memory comes from ``--gpu-memory`` (``8G``, ``512M``, bytes), else from
``nvidia-smi`` where there is one; a software renderer (llvmpipe) draws from main memory, so the
memory available to this process stands for it there.

Before loading, :func:`grid_routes` gives the memory plan's routes (:mod:`geoshade.io.plan`)
from a case's header alone: in memory, from a store (``geoshade grid ingest``), a store's
coarse level, on a cluster; the GPU bytes of each come from the same :func:`gpu_plan` with the
visible faces a store's index counted, else :func:`estimated_faces`.  Calibration (peak RSS /
address space of ``geoshade grid render --size 320x240`` on the synthetic grids of
:func:`~geoshade.compute.grid.synthetic.synthetic_grid`, 5 % inactive, 2 faults; 2-core llvmpipe
machine; docs/NOTES.md "Memory plan" has the commands):

=================================  ==========  =========  ===========  ================
run                                visible     peak RSS   peak VM      estimate (RSS)
                                   faces
=================================  ==========  =========  ===========  ================
EGRID 250 k cells, in memory       51,328      229 MiB    881 MiB      230 MiB
EGRID 1 M cells, in memory         159,008     309 MiB    962 MiB      305 MiB
EGRID 4 M cells, in memory         347,930     602 MiB    1496 MiB     606 MiB
GRDECL 250 k cells, in memory      51,328      231 MiB    954 MiB      261 MiB
GRDECL 1 M cells, in memory        159,008     432 MiB    1343 MiB     433 MiB
GRDECL 4 M cells, in memory        347,930     605 MiB    1571 MiB     734 MiB
store 1 M cells (indexed)          159,008     403 MiB    1713 MiB     403 MiB
store 4 M cells (indexed)          347,930     428 MiB    1721 MiB     426 MiB
store 4 M, local:2 --distributed   347,930     1219 MiB   (3 procs)    1203 MiB (all)
=================================  ==========  =========  ===========  ================

In memory: :data:`MEMORY_BASE` + :data:`MEMORY_CELL` a cell (ZCORN, ACTNUM, the INIT arrays,
the face search), a GRDECL's text parsed in up to four 16 MiB chunks held twice; from a store:
:data:`STORE_BASE` + :data:`STORE_FACE` a visible face (the index's faces, their colours and
the drawing's buffers); the address space adds :data:`MEMORY_VM` or :data:`STORE_VM`.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
from pathlib import Path

import numpy as np

from geoshade.compute.grid.faces import visible_faces
from geoshade.errors import InputError
from geoshade.grid.lod import coarse_level, preview_factor
from geoshade.io.plan import GIB, MIB, Header, Route
from geoshade.io.stores.grid_store import open_grid_store
from geoshade.render.visuals.grid.layout import gpu_plan
from geoshade.styles.checks import parse_bytes  # noqa: F401  (its home before: info, tests)

#: (approach, ZCORN bits, ZCORN store) of every variant the renderer has
VARIANTS = ((1, 16, "faces"), (2, 16, "faces"), (2, 32, "faces"), (3, 16, "grid"),
            (3, 32, "grid"), (3, 16, "faces"), (3, 32, "faces"))


def device_memory() -> tuple[int | None, str]:
    """(bytes, where from) of the GPU this machine draws with, or (None, why unknown).

    ``nvidia-smi``'s free memory of the first GPU where there is one; else None (a software
    renderer's "GPU memory" is main memory: the caller may say so).
    """
    exe = shutil.which("nvidia-smi")
    if exe:
        try:
            r = subprocess.run([exe, "--query-gpu=memory.free,name", "--format=csv,noheader,"
                                "nounits"], capture_output=True, text=True, timeout=10)
            first = r.stdout.strip().splitlines()[0]
            free, name = first.split(",", 1)
            return int(float(free) * 2**20), f"nvidia-smi: {name.strip()}, free"
        except (OSError, subprocess.SubprocessError, ValueError, IndexError):
            pass
    return None, "unknown (no nvidia-smi; give --gpu-memory)"


def cells_with_faces(cells: np.ndarray, dims) -> int:
    """How many distinct cells the ``(n, 3)`` face cells name (one bit a cell, no sort)."""
    nx, ny, nz = dims
    c = np.asarray(cells)
    seen = np.zeros(nx * ny * nz, bool)
    for f0 in range(0, len(c), 1 << 22):  # batches of faces
        b = c[f0:f0 + (1 << 22)].astype(np.int64)
        seen[b[:, 0] + nx * (b[:, 1] + ny * b[:, 2])] = True
    return int(np.count_nonzero(seen))


def gpu_plans(grid, faces=None, gpu_memory: int | None = None) -> dict:
    """Bytes of every approach for ``grid`` (its visible faces: ``faces``, a ``FaceSet``, or
    those of the active cells) and whether each fits ``gpu_memory``.

    Returns
    -------
    dict
        ``faces``, ``cells_drawn``, ``gpu_memory`` (None if unknown) and ``rows``: one dict per
        variant (``approach``, ``zcorn_bits``, ``zcorn_store``, ``bytes``, ``plan`` by object,
        ``fits`` True/False/None).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> p = gpu_plans(synthetic_grid(10, 8, 4), gpu_memory=2**20)
    >>> [(r["approach"], r["zcorn_store"], r["fits"]) for r in p["rows"]][-1]
    (3, 'faces', True)
    """

    fs = visible_faces(grid) if faces is None else faces
    n_faces = len(fs.face)
    drawn = cells_with_faces(fs.cells, grid.dims)
    rows = []
    for approach, bits, store in VARIANTS:
        plan = gpu_plan(approach, grid.dims, n_faces, drawn, bits, store)
        total = int(sum(plan.values()))
        rows.append({"approach": approach, "zcorn_bits": None if approach == 1 else bits,
                     "zcorn_store": store if approach == 3 else None, "bytes": total,
                     "plan": plan,
                     "fits": None if gpu_memory is None else total <= gpu_memory})
    return {"faces": n_faces, "cells_drawn": drawn, "gpu_memory": gpu_memory, "rows": rows}


def format_plans(p: dict, source: str = "") -> str:
    """The plans as a small text table (``geoshade info --gpu``)."""
    mem = p["gpu_memory"]
    head = (f"GPU plan: {p['faces']:,} visible faces of {p['cells_drawn']:,} cells; device "
            f"memory {_size(mem) if mem else 'unknown'}{f' ({source})' if source else ''}")
    lines = [head, "  approach  ZCORN       GPU bytes     fits"]
    for r in p["rows"]:
        name = f"{r['approach']}" + (f" {r['zcorn_store']}" if r["zcorn_store"] else "")
        bits = f"{r['zcorn_bits']}-bit" if r["zcorn_bits"] else "nodes"
        fits = {True: "yes", False: "NO", None: "?"}[r["fits"]]
        lines.append(f"  {name:<9} {bits:<8} {_size(r['bytes']):>12}     {fits}")
    return "\n".join(lines)


def _size(n: int) -> str:
    """>>> _size(512), _size(3 * 2**10), _size(5 * 2**20), _size(3 * 2**30)
    ('512 B', '3.0 KiB', '5.0 MiB', '3.00 GiB')
    """
    if n >= 2**30:
        return f"{n / 2**30:.2f} GiB"
    return f"{n / 2**20:.1f} MiB" if n >= 2**20 else (f"{n / 2**10:.1f} KiB" if n >= 2**10
                                                       else f"{n} B")


def check_fits(plan_bytes: int, gpu_memory: int | None, approach: int, store: str | None,
               name: str = "grid") -> None:
    """One line, before any GPU object, when the chosen approach's plan exceeds the memory."""
    if gpu_memory is not None and plan_bytes > gpu_memory:
        what = f"approach {approach}" + (f" ({store})" if store else "")
        raise InputError(f"{name}: {what} needs {_size(plan_bytes)} of GPU memory, more than "
                         f"the {_size(gpu_memory)} given (gpu_memory); `geoshade info "
                         f"{name} --gpu` lists every approach's needs, or filter/slice the grid")


# --- the memory plan's routes (before loading) ---------------------------------------------------
#: resident memory of an in-memory grid render besides the grid (measured, see the module)
MEMORY_BASE = 205 * MIB
#: resident bytes per cell of a grid in memory (ZCORN 32, ACTNUM, INIT arrays, faces search)
MEMORY_CELL = 105
#: a GRDECL file is parsed in chunks of 16 MiB; up to four are held at once, twice
GRDECL_CHUNKS = 4 * (16 * MIB)
#: address space beyond the resident memory, in memory and from a store (libraries, threads)
MEMORY_VM = int(0.95 * GIB)
STORE_VM = int(1.35 * GIB)
#: resident memory of a render from an indexed store besides its faces (measured)
STORE_BASE = 383 * MIB
#: resident bytes per visible face drawn from a store (index records, colours, buffers)
STORE_FACE = 130
#: resident memory of one local worker of a ``--distributed`` render besides its faces
WORKER_BASE = 430 * MIB
#: visible faces of a grid whose count is unknown: this many times its outer shell's (the
#: synthetic grids: 1.56–1.59, inactive blobs and faults adding inner faces)
FACE_SHELL = 1.6


def estimated_faces(dims, nactive: int | None = None) -> int:
    """Visible faces of a ``dims`` grid when no index counts them: :data:`FACE_SHELL` times the
    faces of its outer shell (scaled down with the inactive share).

    >>> estimated_faces((200, 200, 25))
    160000
    """
    nx, ny, nz = (int(v) for v in dims)
    shell = 2 * (nx * ny + ny * nz + nx * nz)
    share = 1.0 if nactive is None else min(1.0, nactive / max(nx * ny * nz, 1) / 0.95)
    return int(FACE_SHELL * shell * share)


def _gpu(dims, faces: int, options) -> int:
    approach = int(getattr(options, "approach", 3) or 3)
    bits = int(getattr(options, "zcorn_bits", 16) or 16)
    store = getattr(options, "zcorn_store", "faces") or "faces"
    return int(sum(gpu_plan(approach, dims, faces, faces, bits, store).values()))


def _store_name(path) -> str:
    p = Path(str(path))
    return str(p.with_suffix(".zarr")) if p.suffix else str(p) + ".zarr"


def _coarse(store: str, header: Header):
    """The store's coarse level, opened out of core (one line when it cannot be used)."""
    fine = open_grid_store(store)
    level, why = coarse_level(fine)
    if level is None:
        raise InputError(f"{store}: {why or 'no coarse level'}")
    c = header.coarse or {}
    f = c.get("factor", "?")
    return dataclasses.replace(level, name=f"{Path(store).name} (coarse level, cells merged "
                                            f"{f}×{f}×{f})")


def grid_routes(header: Header, options=None, workers: int = 2) -> list[Route]:
    """The routes of a grid case or grid store ``header`` for a picture with ``options``:
    in memory (a case) or from the store, the store's coarse level, a cluster of ``workers``
    local workers; each with resident memory, address space and GPU bytes."""
    dims = tuple(int(v) for v in header.shape)
    ncells = dims[0] * dims[1] * dims[2]
    faces = header.faces if header.faces is not None else estimated_faces(dims, header.nactive)
    gpu = _gpu(dims, faces, options)
    store_ram = STORE_BASE + STORE_FACE * faces
    exact = header.faces is not None   # an estimate of the GPU bytes is shown, not judged: the
    routes = []                        # View refuses a plan beyond gpu_memory from its faces
    if header.kind == "grid":
        parse = 2 * min(header.file_bytes, GRDECL_CHUNKS) if header.format in ("grdecl",
                                                                               "deck") else 0
        ram = MEMORY_BASE + MEMORY_CELL * ncells + parse
        routes.append(Route("memory", "in memory", ram, ram + MEMORY_VM, gpu, gpu_binding=False))
        target = _store_name(header.path)
        how = f"geoshade grid ingest {header.path} -o {target} --coarse auto, then render {target}"
        routes.append(Route("store", "from a store", store_ram, store_ram + STORE_VM, gpu,
                            ready=False, how=how, gpu_binding=False))
        f = preview_factor(ncells)
        if f is not None:
            cdims = tuple(-(-n // f) for n in dims)
            cfaces = estimated_faces(cdims)
            cram = STORE_BASE + STORE_FACE * cfaces
            routes.append(Route("coarse", "from a store's coarse level", cram, cram + STORE_VM,
                                _gpu(cdims, cfaces, options), ready=False, how=how,
                                gpu_binding=False,
                                reduced=f"coarse level: cells merged {f}×{f}×{f}"))
    else:
        routes.append(Route("store", "from the store", store_ram, store_ram + STORE_VM, gpu,
                            gpu_binding=exact))
        c = header.coarse
        if c is not None:
            cdims = tuple(int(v) for v in c["dims"])
            cfaces = c.get("faces") or estimated_faces(cdims)
            cram = STORE_BASE + STORE_FACE * cfaces
            f = c["factor"]
            routes.append(Route(
                "coarse", "from the store's coarse level", cram, cram + STORE_VM,
                _gpu(cdims, cfaces, options), gpu_binding=c.get("faces") is not None,
                reduced=f"coarse level: cells merged {f}×{f}×{f}, "
                        f"{'×'.join(map(str, cdims))} of {'×'.join(map(str, dims))} cells",
                load=lambda: _coarse(header.path, header)))
    n = max(1, int(workers))
    here = routes[0].ram if header.kind == "grid" else 300 * MIB   # a case is read here
    cluster = here + n * WORKER_BASE + STORE_FACE * faces
    distributed = bool(getattr(options, "distributed", False))
    routes.append(Route("cluster", f"on {n} local workers", cluster, cluster + n * STORE_VM,
                        gpu, ready=distributed, gpu_binding=exact,
                        how=f"--scheduler local:{n} --distributed"
                            + (" on the store" if header.kind == "grid" else "")))
    return routes
