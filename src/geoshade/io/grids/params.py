"""Property files added to any corner-point grid (``--param FILE``, repeatable): ROFF parameter
files (any name; RMS exports ``GRID--name.roff`` beside the grid, but a file called
``poro.roff`` is read just as well) and GRDECL property files (``PORO``, ``PERMX``... keywords of
one value a cell).

The format is found from the suffix (``.roff``, ``.roffbin``, ``.roffasc``: ROFF; anything else
is read as GRDECL text). Each file must be for the grid's size; its properties are added to the
grid (a name the grid already has is replaced, and one warning says so), the ROFF code names go
into ``meta["codes"]`` and the files read into ``meta["param_files"]``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.grdecl import GridBuilder
from geoshade.io.grids.roff import ROFF_SUFFIXES, read_roff_parameters
from geoshade.models import CornerPointGrid


def read_grdecl_properties(path, dims) -> dict[str, np.ndarray]:
    """The cell properties of a GRDECL property file (``PORO``, ``PERMX``, ``FACIES``...:
    keywords each followed by nx·ny·nz numbers, ``N*value`` repeats, BOX and the edit keywords
    as in a grid file; INCLUDEs followed) for a grid of ``dims`` (nx, ny, nz).

    Returns
    -------
    dict
        name -> (nx, ny, nz) array, F-order (float32; int32 for ``*NUM`` keywords).

    Raises
    ------
    InputError
        No property of the grid's size in the file (a count that is not nx·ny·nz is named for
        the known keywords), or the reader's one-line errors.

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "poro.grdecl")
    >>> _ = open(f, "w").write("PORO\\n 0.1 0.2 2*0.3 /\\nFIPNUM\\n 4*2 /\\n")
    >>> props = read_grdecl_properties(f, (2, 1, 2))
    >>> props["PORO"][:, 0, 1].tolist(), props["FIPNUM"].dtype.name
    ([0.30000001192092896, 0.30000001192092896], 'int32')
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file")
    builder = GridBuilder(p)
    builder.dims = tuple(int(n) for n in dims)
    builder.parse_all()   # a SPECGRID of another size is refused there
    if not builder.props:
        nx, ny, nz = dims
        skipped = f" (keywords read over: {', '.join(builder.skipped)})" if builder.skipped else ""
        raise InputError(f"{path}: no cell property of {nx}×{ny}×{nz} = {nx * ny * nz} values"
                         f"{skipped}; expected keywords such as PORO followed by one value a "
                         "cell and '/'")
    return dict(builder.props)


def read_param_file(path, dims) -> tuple[dict, dict]:
    """``(properties, codes)`` of one property file for a grid of ``dims`` (nx, ny, nz):
    name -> (nx, ny, nz) F-order array, and name -> {code: code name} (ROFF discrete
    parameters; empty for GRDECL).

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "ntg.inc")
    >>> _ = open(f, "w").write("NTG\\n 2*0.5 /\\n")
    >>> props, codes = read_param_file(f, (1, 1, 2))
    >>> list(props), props["NTG"].shape, codes
    (['NTG'], (1, 1, 2), {})
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{path}: no such file (--param)")
    if p.suffix.lower() in ROFF_SUFFIXES:
        return read_roff_parameters(p, tuple(dims))
    return read_grdecl_properties(p, dims), {}


def add_params(grid: CornerPointGrid, paths) -> CornerPointGrid:
    """``grid`` with the properties of the files ``paths`` added (in place; returned).

    Raises
    ------
    InputError
        A missing file, a file for another grid size, a file without properties: one line
        naming the file.

    Examples
    --------
    >>> import os, tempfile
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(2, 1, 1)
    >>> f = os.path.join(tempfile.mkdtemp(), "facies.grdecl")
    >>> _ = open(f, "w").write("FACIES\\n 1 2 /\\n")
    >>> add_params(g, [f]).properties["FACIES"].ravel().tolist()
    [1.0, 2.0]
    """
    replaced = []
    for path in paths or ():
        props, codes = read_param_file(path, grid.dims)
        replaced += [f"{n} ({path})" for n in props if n in grid.properties]
        grid.properties.update(props)
        if codes:
            grid.meta.setdefault("codes", {}).update(codes)
        grid.meta.setdefault("param_files", []).append(str(path))
    if replaced:
        warnings.warn(f"{grid.name or 'grid'}: --param replaced the grid's own "
                      f"{', '.join(replaced)}", UserWarning, stacklevel=2)
    return grid


__all__ = ["add_params", "read_grdecl_properties", "read_param_file"]
