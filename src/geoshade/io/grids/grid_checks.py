"""Checks shared by the corner-point readers (GRDECL, decks, EGRID/INIT/UNRST): memory before a
large allocation, and the one warning about inverted cells.

A grid's size comes from one header (SPECGRID, DIMENS, GRIDHEAD); ``SPECGRID 100000 100000
100000`` asks for 447 GiB of ZCORN alone.  The readers check what an array needs against the
memory this machine has available (:func:`geoshade.io.paths.check_memory`: ``MemAvailable``, or
less under a cgroup limit) before allocating it, and say how much is needed; the binary reader
also checks every array against the bytes left in its file (:mod:`geoshade.io.grids.ecl_records`).
A GRDECL file is not bounded by its length: ``N*value`` repeats let a short file describe a large
grid legally.
"""

from __future__ import annotations

import warnings

from geoshade.io import paths
from geoshade.models import CornerPointGrid

#: allocations below this many bytes are not checked (reading /proc/meminfo costs ~50 µs)
CHECK_BYTES = 64 << 20


def check_memory(path, what: str, nbytes: int) -> None:
    """Refuse in one line (:class:`geoshade.io.paths.NotEnoughMemoryError`, exit code 4) an
    allocation of ``nbytes`` that the memory available cannot hold; ``what`` says what it is
    for (``"ZCORN (8e+15 values)"``).  Allocations below :data:`CHECK_BYTES` pass unchecked.

    Examples
    --------
    >>> check_memory("g.grdecl", "ZCORN", 100)               # small: not even looked at
    >>> try:
    ...     check_memory("g.grdecl", "the grid of SPECGRID 100000×100000×100000", 2**62)
    ... except paths.NotEnoughMemoryError as err:
    ...     print(str(err).split(" of memory")[0])
    g.grdecl: reading the grid of SPECGRID 100000×100000×100000 needs 4096.0 PiB
    """
    if nbytes >= CHECK_BYTES:
        paths.check_memory(int(nbytes), path, what)


def grid_bytes(dims) -> int:
    """Bytes of a grid's geometry in memory: ZCORN (8 float32 a cell), ACTNUM (1 byte a cell)
    and COORD (6 float64 a pillar)."""
    nx, ny, nz = (int(v) for v in dims)
    return 33 * nx * ny * nz + 48 * (nx + 1) * (ny + 1)


def check_grid_size(path, keyword: str, dims) -> None:
    """:func:`check_memory` for the geometry of a ``dims`` grid, named by its header keyword."""
    nx, ny, nz = (int(v) for v in dims)
    check_memory(path, f"the grid of {keyword} {nx}×{ny}×{nz} ({nx * ny * nz:.3g} cells: ZCORN, "
                       "COORD and ACTNUM)", grid_bytes(dims))


def warn_inverted(grid: CornerPointGrid, path) -> None:
    """One warning when active cells are inverted (a corner's bottom above its top); the count
    goes to ``grid.meta["inverted_cells"]``.  Such cells are drawn as given (their corners
    span the same hexahedron, its faces wound the other way)."""
    n, first = grid.inverted_cells()
    if not n:
        return
    grid.meta["inverted_cells"] = n
    i, j, k = (v + 1 for v in first or (0, 0, 0))
    warnings.warn(f"{path}: ZCORN: {n} of {grid.nactive} active cells are inverted (a bottom "
                  f"corner above its top; first: cell i={i} j={j} k={k}); they are drawn as "
                  "given", stacklevel=3)
