"""GPU memory of a grid before anything is allocated: each approach's bytes, and whether they fit.

:func:`gpu_plans` counts the visible faces on the CPU (:func:`geoshade.compute.grid_faces.
visible_faces`, the numba kernel at scale) and sizes every GPU object of every approach with
:func:`geoshade.render.visuals.grid.layout.gpu_plan` — the function whose sizes the renderer
allocates (a test checks ``GpuCache.breakdown() == plan``).  ``geoshade info CASE --gpu`` prints
it; ``GridView`` refuses, before its first GPU object, a plan larger than ``gpu_memory``.

The device's memory comes from ``--gpu-memory`` (``8G``, ``512M``, bytes), else from
``nvidia-smi`` where there is one; a software renderer (llvmpipe) draws from main memory, so the
memory available to this process stands for it there.
"""

from __future__ import annotations

import shutil
import subprocess

import numpy as np

from geoshade.compute.grid_faces import visible_faces
from geoshade.errors import InputError
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
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
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
