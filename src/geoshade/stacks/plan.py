"""The stacks' route for the memory plan (:mod:`geoshade.io.plan`): a stack model is drawn from
memory, its intervals packed into the chosen layout on the GPU; its resident memory, address
space and GPU bytes from the ``.stacks.npz`` header (columns, intervals), the GPU bytes from
:func:`geoshade.compute.stacks.layout_plan` (the sizes the visual allocates).

A stack model has one route: when it does not fit, the plan refuses in one line with its
figures (a smaller model is made with ``geoshade stacks convert`` from a smaller box).

Calibration (``geoshade stacks render --size 320x240``, ssbo layout, models of
:func:`~geoshade.compute.stacks.synthetic_layers` with 6 layers and 40 levels; 2-core llvmpipe
machine, ``/proc/PID/status`` ``VmHWM``/``VmPeak``; docs/NOTES.md "Memory plan"):

========================================  =========  ========  ==============
model                                     peak RSS   peak VM   estimate (RSS)
========================================  =========  ========  ==============
256×256 columns, 309,335 intervals        187 MiB    843 MiB   186 MiB
1024×1024 columns, 4,949,280 intervals    431 MiB    1062 MiB  434 MiB
2048×2048 columns, 19,797,116 intervals   1229 MiB   1858 MiB  1228 MiB
========================================  =========  ========  ==============

RSS = :data:`BASE` + :data:`INTERVAL` bytes an interval (the model, its GPU intervals, the
packed layout and the software renderer's copy); the address space adds :data:`VM_EXTRA`.
"""

from __future__ import annotations

import math

from geoshade.compute.stacks import layout_plan
from geoshade.errors import GeoshadeError
from geoshade.io.plan import GIB, MIB, Header, Route

#: resident memory of a stacks render besides the model (measured, see the module)
BASE = 169 * MIB
#: resident bytes per interval of the model (measured)
INTERVAL = 56
#: address space beyond the resident memory (libraries, thread stacks and arenas)
VM_EXTRA = int(0.65 * GIB)


def stacks_routes(header: Header, options=None) -> list[Route]:
    """The one route of a stack model ``header``: in memory (an empty list for a header that
    is not a stack model)."""
    if header.kind != "stacks" or header.intervals is None:
        return []
    nx, ny = (int(v) for v in header.shape[:2])
    n = int(header.intervals)
    layout = getattr(options, "layout", None) or "ssbo"
    m = max(1, math.ceil(2 * n / max(nx * ny, 1)))
    try:
        gpu = int(layout_plan(layout, (nx, ny), n, m)["consumed"])
    except GeoshadeError:   # beyond a texture or buffer limit: the View says which
        gpu = None
    ram = BASE + INTERVAL * n
    return [Route("memory", "in memory", ram, ram + VM_EXTRA, gpu)]


__all__ = ["BASE", "INTERVAL", "VM_EXTRA", "stacks_routes"]
