"""ROFF grids and parameters (the format RMS exports), read through :mod:`roffio` (the ``roff``
extra).

A ROFF grid stores corner-point geometry in its own layout, converted here to the
:class:`~geoshade.models.CornerPointGrid` one (ECLIPSE's COORD/ZCORN):

- ``cornerLines``: per pillar (i slowest, then j) the **bottom** then the **top** point, in local
  coordinates; map coordinates are ``(local + translate) * scale`` (``zscale`` is -1: depth);
- ``zvalues``: per node (pillar i, j and level k, k fastest and **from the bottom up**) 1 value
  (``splitEnz`` 1: the four cells around the pillar meet there) or 4 (``splitEnz`` 4: a fault;
  the cells south-west, south-east, north-west and north-east of the pillar, in that order);
- ``active``, and parameters, one value a cell in C order (i slowest, k fastest, from the bottom).

Splits 2 and 8 (vertical splits) are refused in one line, as xtgeo and ResInsight do: RMS does
not write them.  Parameters: ``-999`` (``255`` in byte parameters) is undefined; float ones
become NaN there, discrete ones keep ``-999`` (an integer property has no NaN, and 0 is often a
facies code); their code names go to ``grid.meta["codes"]``.

Properties come from the parameter files given (``properties=[...]``) or, by default, from the
files beside the grid named ``GRID--NAME.roff`` (the FMU convention RMS exports follow); a
parameter file opened on its own opens its grid that way.  Tested against xtgeo reading the same
files: corners, ACTNUM and parameters equal.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import GeoshadeError, InputError, require
from geoshade.io.grids.grid_checks import check_grid_size, warn_inverted
from geoshade.io.paths import check_file
from geoshade.models import CornerPointGrid

#: file suffixes of ROFF files (binary or ASCII; the content says which)
ROFF_SUFFIXES = (".roff", ".roffasc", ".roffbin")
#: undefined values of ROFF parameters (float, integer, byte)
UNDEFINED = {"f": -999.0, "i": -999, "u": 255}
#: pillars per block while ZCORN is built (bounds the temporaries on large grids)
_BLOCK_NODES = 1 << 22


def _roffio():
    return require("roffio", "roff", "reading ROFF files")


def _read_tags(path: Path, what: str) -> list[tuple[str, dict[str, Any]]]:
    """Every tag of a ROFF file as (name, {key: value}); the grid's size is checked against
    the memory available as soon as its ``dimensions`` tag is read (before the arrays)."""
    roffio = _roffio()
    check_file(path, what)
    tags: list[tuple[str, dict[str, Any]]] = []
    try:
        with roffio.lazy_read(str(path)) as gen:
            for tag, keys in gen:
                values: dict[str, Any] = {}
                for key in keys:  # every value read in order (skipping one confuses roffio)
                    values[key[0]] = key[1]
                tags.append((tag, values))
                if tag == "dimensions":
                    check_grid_size(path, "dimensions", _dims(path, values))
    except GeoshadeError:
        raise
    except Exception as err:  # roffio's TokenizationError, RoffSyntaxError, ..., numpy's
        text = (str(err).strip().splitlines() or [type(err).__name__])[0][:160]
        raise InputError(f"{path}: damaged ROFF file ({type(err).__name__}: {text}); expected "
                         f"{what}") from None
    return tags


def _dims(path: Path, values: dict) -> tuple[int, int, int]:
    try:
        dims = tuple(int(values[k]) for k in ("nX", "nY", "nZ"))
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{path}: dimensions: expected nX, nY, nZ, got "
                         f"{', '.join(values) or 'nothing'}") from None
    if min(dims) < 1:
        raise InputError(f"{path}: dimensions: {'×'.join(map(str, dims))} is not positive")
    return dims[0], dims[1], dims[2]


def _first(tags, name: str) -> dict[str, Any] | None:
    return next((v for t, v in tags if t == name), None)


def _need(path: Path, tags, tag: str, key: str, size: int | None = None):
    values = _first(tags, tag)
    if values is None or key not in values:
        raise InputError(f"{path}: {tag} {key}: not found; expected a ROFF grid (filetype "
                         "grid: dimensions, cornerLines, zvalues)")
    v = values[key]
    n = len(v)
    if size is not None and n != size:
        raise InputError(f"{path}: {tag} {key}: expected {size} values, got {n}")
    return v


def _filetype(tags) -> str:
    return str((_first(tags, "filedata") or {}).get("filetype", ""))


def _bytes(v) -> np.ndarray:
    return np.frombuffer(v, np.uint8) if isinstance(v, bytes | bytearray) else np.asarray(v)


def _zcorn(path: Path, dims, split: np.ndarray, zvals: np.ndarray, zoffset: float,
           zscale: float) -> np.ndarray:
    """ZCORN (2nx, 2ny, 2nz) float32, F-order, from ROFF's per-node z values."""
    nx, ny, nz = dims
    bad = (split != 1) & (split != 4)
    if bad.any():
        q = int(np.flatnonzero(bad)[0])
        i, rest = divmod(q, (ny + 1) * (nz + 1))
        j, k = divmod(rest, nz + 1)
        raise InputError(f"{path}: zvalues splitEnz: value {int(split[q])} at node i={i + 1} "
                         f"j={j + 1} k={nz + 1 - k} (pillar i, j; level k from the top); expected "
                         "1 or 4 (splits 2 and 8 are not read, as by xtgeo and ResInsight)")
    need = int(split.sum(dtype=np.int64))
    if zvals.size != need:
        raise InputError(f"{path}: zvalues data: expected {need} values (the sum of splitEnz), "
                         f"got {zvals.size}")
    zcorn = np.empty((2 * nx, 2 * ny, 2 * nz), np.float32, order="F")
    per = (ny + 1) * (nz + 1)  # nodes a pillar row (one i)
    step = max(1, _BLOCK_NODES // per)
    off, zo, zs = 0, np.float32(zoffset), np.float32(zscale)
    four = np.arange(4)
    for i0 in range(0, nx + 1, step):
        i1 = min(nx + 1, i0 + step)
        s = split[i0 * per:i1 * per].astype(np.int64)
        start = off + np.cumsum(s) - s
        off += int(s.sum())
        z = zvals[start[:, None] + np.where(s[:, None] == 4, four, 0)]
        z = ((z + zo) * zs).reshape(i1 - i0, ny + 1, nz + 1, 4)[:, :, ::-1]  # k from the top
        for a in (0, 1):  # cell i's corner a lies on pillar i + a
            lo, hi = max(i0 - a, 0), min(i1 - a, nx)
            if lo >= hi:
                continue
            for b in (0, 1):
                q = 2 * (1 - b) + (1 - a)  # the cell is north (b=0) / east (a=0) of the pillar
                for c in (0, 1):
                    zcorn[2 * lo + a:2 * hi:2, b::2, c::2] = \
                        z[lo + a - i0:hi + a - i0, b:b + ny, c:c + nz, q]
    return zcorn


def _scalars(tags, tag: str, keys, default) -> list[float]:
    values = _first(tags, tag) or {}
    return [float(values.get(k, d)) for k, d in zip(keys, default, strict=True)]


def _cells(values: np.ndarray, dims) -> np.ndarray:
    """A ROFF cell array (C order, k from the bottom) -> (nx, ny, nz) F-order, k from the top."""
    return np.asfortranarray(values.reshape(dims)[:, :, ::-1])


def _parameters(path: Path, tags, dims) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
    """The parameters of a ROFF file: name -> cell array, and name -> {code: code name}."""
    props: dict[str, np.ndarray] = {}
    codes: dict[str, dict] = {}
    for tag, values in tags:
        if tag != "parameter":
            continue
        name = str(values.get("name", "")).strip()
        if not name or "data" not in values:
            raise InputError(f"{path}: parameter {name or '(unnamed)'}: expected a name and "
                             "data")
        raw = _bytes(values["data"])
        n = dims[0] * dims[1] * dims[2]
        if raw.size != n:
            raise InputError(f"{path}: parameter {name}: expected {n} values "
                             f"({'×'.join(map(str, dims))} cells), got {raw.size}")
        kind = raw.dtype.kind
        if kind == "f":
            v = raw.astype(np.float32 if raw.dtype.itemsize <= 4 else np.float64)
            v[v == UNDEFINED["f"]] = np.nan
        elif kind in "iub":
            v = raw.astype(np.int32)
            if kind == "u":
                v[raw == UNDEFINED["u"]] = UNDEFINED["i"]
        else:
            raise InputError(f"{path}: parameter {name}: values of type {raw.dtype}; expected "
                             "float, int or byte")
        if name in props:
            raise InputError(f"{path}: parameter {name}: found twice")
        props[name] = _cells(v, dims)
        if "codeValues" in values and "codeNames" in values:
            codes[name] = {int(c): str(s) for c, s in
                           zip(np.asarray(values["codeValues"]).tolist(),
                               list(values["codeNames"]), strict=False)}
    return props, codes


def _siblings(path: Path) -> list[Path]:
    """Parameter files beside a grid named ``GRID--NAME.roff`` (the FMU convention)."""
    stem = path.name[: -len(path.suffix)]
    pattern = re.compile(re.escape(stem) + r"--.+(" + "|".join(
        re.escape(s) for s in ROFF_SUFFIXES) + ")", re.IGNORECASE)
    return sorted(f for f in path.parent.iterdir() if pattern.fullmatch(f.name) and f.is_file())


def read_roff_parameters(path, dims=None) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
    """The parameters of a ROFF parameter file: name -> (nx, ny, nz) array (F-order, k from the
    top as in the grid), and name -> {code: name} for discrete ones.

    ``dims``: the grid's size; a file for another size is one line.

    Examples
    --------
    >>> import os, tempfile, numpy as np, roffio
    >>> f = os.path.join(tempfile.mkdtemp(), "g--poro.roff")
    >>> roffio.write(f, {"filedata": {"filetype": "parameter"},
    ...                  "dimensions": {"nX": 1, "nY": 1, "nZ": 2},
    ...                  "parameter": {"name": "PORO", "data": np.float32([-999.0, 0.3])}})
    >>> props, codes = read_roff_parameters(f, (1, 1, 2))
    >>> props["PORO"][0, 0].tolist()      # k from the top; -999 is undefined
    [0.30000001192092896, nan]
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    tags = _read_tags(p, "a ROFF parameter file")
    d = _first(tags, "dimensions")
    if d is None:
        raise InputError(f"{path}: dimensions: not found; expected a ROFF parameter file")
    own = _dims(p, d)
    if dims is not None and tuple(dims) != own:
        raise InputError(f"{path}: dimensions: the parameters are for a "
                         f"{'×'.join(map(str, own))} grid; expected "
                         f"{'×'.join(map(str, dims))} (the grid's)")
    if not any(t == "parameter" for t, _ in tags):
        raise InputError(f"{path}: parameter: not found; expected a ROFF parameter file "
                         f"(filetype {_filetype(tags) or 'unknown'})")
    return _parameters(p, tags, own)


def read_roff(path, properties=None) -> CornerPointGrid:
    """A ROFF grid (RMS), with its properties, as a :class:`~geoshade.models.CornerPointGrid`.

    Parameters
    ----------
    path : str or Path
        ``.roff`` (binary or ASCII), ``.roffasc``, ``.roffbin``: a grid file, or a parameter
        file ``GRID--NAME.roff`` whose grid ``GRID.roff`` lies beside it.
    properties : list of str or Path, optional
        ROFF parameter files to read as cell properties (each may hold several parameters).
        Default: the files ``GRID--*.roff`` beside the grid; ``[]``: none.

    Returns
    -------
    CornerPointGrid
        COORD float64, ZCORN float32 (depths: ``(z + zoffset) * zscale``), ACTNUM; the
        parameters of the grid file and of ``properties``; ``meta``: ``format`` "ROFF",
        ``source``, ``files`` (the parameter files read), ``codes``, ``subgrids`` (layers per
        subgrid from the top).

    Raises
    ------
    InputError
        A damaged file, a missing tag, sizes that do not agree, splits other than 1 and 4
        (one line naming the file and the tag).
    MissingExtraError
        roffio is not installed (``pip install 'geoshade[roff]'``).

    Examples
    --------
    >>> import os, tempfile, numpy as np
    >>> import roffio
    >>> f = os.path.join(tempfile.mkdtemp(), "box.roff")
    >>> lines = np.array([[0, 0, 0, 0, 0, 1], [0, 1, 0, 0, 1, 1],
    ...                   [1, 0, 0, 1, 0, 1], [1, 1, 0, 1, 1, 1]], np.float32).ravel()
    >>> roffio.write(f, {"filedata": {"filetype": "grid"},
    ...                  "dimensions": {"nX": 1, "nY": 1, "nZ": 1},
    ...                  "cornerLines": {"data": lines},
    ...                  "zvalues": {"splitEnz": b"\\x01" * 8,      # z: -2 (bottom), -1 (top)
    ...                              "data": np.array([-2, -1] * 4, np.float32)}})
    >>> g = read_roff(f)
    >>> g.dims, float(g.zcorn[0, 0, 0]), float(g.zcorn[0, 0, 1])     # top and bottom depth
    ((1, 1, 1), 1.0, 2.0)
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    tags = _read_tags(p, "a ROFF grid file")
    if _filetype(tags) == "parameter":
        m = re.fullmatch(r"(.+?)--.+", p.name[: -len(p.suffix)])
        owner = next((p.parent / (m[1] + s) for s in (p.suffix, *ROFF_SUFFIXES)
                      if (p.parent / (m[1] + s)).is_file()), None) if m else None
        if owner is None:
            raise InputError(f"{path}: a ROFF parameter file, not a grid; open its grid with "
                             "geoshade.load(GRID.roff, properties=[this file])"
                             + (f" (looked for {m[1]}{p.suffix} beside it)" if m else ""))
        return read_roff(owner, properties)
    dims_tag = _first(tags, "dimensions")
    if dims_tag is None:
        raise InputError(f"{path}: dimensions: not found; expected a ROFF grid (filetype grid)")
    dims = _dims(p, dims_tag)
    nx, ny, nz = dims
    n = nx * ny * nz
    lines = np.asarray(_need(p, tags, "cornerLines", "data", 6 * (nx + 1) * (ny + 1)))
    zvals = np.asarray(_need(p, tags, "zvalues", "data"), np.float32)
    zinfo = _first(tags, "zvalues") or {}
    nodes = (nx + 1) * (ny + 1) * (nz + 1)
    split = (_bytes(_need(p, tags, "zvalues", "splitEnz", nodes)).astype(np.uint8)
             if "splitEnz" in zinfo else np.ones(nodes, np.uint8))
    xo, yo, zo = _scalars(tags, "translate", ("xoffset", "yoffset", "zoffset"), (0, 0, 0))
    xs, ys, zs = _scalars(tags, "scale", ("xscale", "yscale", "zscale"), (1, 1, -1))
    zcorn = _zcorn(p, dims, split, zvals, zo, zs)
    pillars = lines.astype(np.float64).reshape(nx + 1, ny + 1, 2, 3)[:, :, ::-1]  # top first
    coord = ((pillars + np.array([xo, yo, zo])) * np.array([xs, ys, zs])).reshape(nx + 1, ny + 1, 6)
    act = _first(tags, "active")
    actnum = None
    if act is not None and "data" in act:
        a = _bytes(_need(p, tags, "active", "data", n))
        actnum = _cells(a != 0, dims).astype(np.uint8)
    props, codes = _parameters(p, tags, dims)
    files = _siblings(p) if properties is None else [Path(f) for f in properties]
    for f in files:
        more, more_codes = read_roff_parameters(f, dims)
        twice = sorted(set(more) & set(props))
        if twice:
            raise InputError(f"{f}: parameter {twice[0]}: already read from another file")
        props.update(more)
        codes.update(more_codes)
    sub = _first(tags, "subgrids")
    meta = {"format": "ROFF", "source": str(p), "files": [str(f) for f in files],
            "codes": codes,
            "subgrids": [int(v) for v in np.asarray(sub["nLayers"]).tolist()]
            if sub and "nLayers" in sub else []}
    grid = CornerPointGrid(coord=coord, zcorn=zcorn, actnum=actnum, properties=props,
                           name=str(p), meta=meta)
    warn_inverted(grid, p)
    return grid
