"""RMS/IRAP classic surfaces (horizons, maps), ASCII and binary, as terrain rasters.

Both forms hold the same header and a grid of node values, ``x`` fastest, row ``j = 0`` at
``yori``, undefined nodes ``9999900.0``:

- **ASCII** (``.fgr``, ``.irapasc``; RMS also writes it as ``.gri``)::

      -996  NY  XINC  YINC
      XORI  XMAX  YORI  YMAX
      NX  ROTATION  XORI  YORI
      0  0  0  0  0  0  0
      v(0,0) v(1,0) ... v(NX-1,0) v(0,1) ...

- **binary** (``.gri``, ``.irap``, ``.irapbin``): big-endian Fortran records (each framed by
  its length in bytes as a 4-byte integer): ``(-996, NY, XORI, XMAX, YORI, YMAX, XINC, YINC)``
  as 2 int32 + 6 float32; ``(NX, ROTATION, XORI, YORI)`` as int32 + 3 float32; 7 int32
  zeros; then the NX·NY float32 values in records of any length.

The kind is told by the file's first bytes, not its name. The origin is read from the second line
(record), as xtgeo reads it (RMS writes it in both places). ``ROTATION`` is the angle in degrees
counter-clockwise from east of the grid's x axis: node ``(i, j)`` lies at ``(XORI, YORI) + i ·
XINC · (cos r, sin r) + j · YINC · (−sin r, cos r)``. The surface is read as a
:class:`~geoshade.io.layers.dem.Raster` (each node the centre of a cell of ``XINC × YINC``); a
rotated one is placed with its rotation, resampled onto a north-up grid over it
(:func:`geoshade.io.layers.dem.unrotate`, rasterio), and ``meta["rotated"]`` says so.

IRAP states neither the sign of its values nor their unit. RMS stores horizons as depth
(positive down), so by default heights are ``−value`` (``positive="up"`` keeps the values as
heights); ``meta["assumed"]`` says what was taken. xtgeo (``xtgeo.surface_from_file``) is the
oracle of the tests.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.layers.dem import Raster, unrotate
from geoshade.io.paths import check_file, check_memory

#: the IRAP header's identifier
IRAP_ID = -996
#: value of an undefined node
UNDEF = 9999900.0
#: the first 8 bytes of a binary IRAP surface: a 32-byte record's length, then -996
BINARY_MAGIC = np.array([32, IRAP_ID], ">i4").tobytes()


def is_irap_binary(path) -> bool:
    """Whether ``path`` starts as a binary IRAP surface does.

    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "s.gri")
    >>> open(f, "w").write("-996 2 1.0 1.0\\n")
    15
    >>> is_irap_binary(f)
    False
    """
    with open(path, "rb") as fh:
        return fh.read(8) == BINARY_MAGIC


def _bad(path, what: str) -> InputError:
    return InputError(f"{path}: {what}; expected an IRAP surface (RMS classic, ASCII or "
                      "binary)")


def _records(buf: bytes, path):
    """Fortran records of ``buf`` (big-endian 4-byte lengths): yields (offset, length)."""
    pos, n = 0, len(buf)
    while pos < n:
        if pos + 4 > n:
            raise _bad(path, f"the file ends inside a record marker at byte {pos}")
        size = int(np.frombuffer(buf, ">i4", 1, pos)[0])
        end = pos + 4 + size
        if size < 0 or end + 4 > n:
            raise _bad(path, f"a record of {size} bytes at byte {pos} runs past the end of the "
                             f"file ({n} bytes): truncated")
        if int(np.frombuffer(buf, ">i4", 1, end)[0]) != size:
            raise _bad(path, f"record at byte {pos}: its closing length differs from {size}")
        yield pos + 4, size
        pos = end + 4


def _read_binary(path) -> tuple[dict, np.ndarray]:
    buf = Path(path).read_bytes()
    recs = _records(buf, path)
    try:
        (o1, s1), (o2, s2), (_, s3) = next(recs), next(recs), next(recs)
    except StopIteration:
        raise _bad(path, "fewer than the 3 header records") from None
    if (s1, s2, s3) != (32, 16, 28):
        raise _bad(path, f"header records of {s1}, {s2}, {s3} bytes (expected 32, 16, 28)")
    i1 = np.frombuffer(buf, ">i4", 2, o1)
    f1 = np.frombuffer(buf, ">f4", 6, o1 + 8).astype(np.float64)
    nx = int(np.frombuffer(buf, ">i4", 1, o2)[0])
    f2 = np.frombuffer(buf, ">f4", 3, o2 + 4).astype(np.float64)
    head = {"ny": int(i1[1]), "xori": f1[0], "xmax": f1[1], "yori": f1[2], "ymax": f1[3],
            "xinc": f1[4], "yinc": f1[5], "nx": nx, "rotation": f2[0]}
    _check_head(head, path)
    n = head["nx"] * head["ny"]
    check_memory(n * 12, path, f"the {head['nx']}×{head['ny']} surface")
    parts, got = [], 0
    for off, size in recs:
        if size % 4:
            raise _bad(path, f"a value record of {size} bytes (not whole float32 values)")
        parts.append(np.frombuffer(buf, ">f4", size // 4, off))
        got += size // 4
    if got != n:
        raise _bad(path, f"{got} values for {head['nx']}×{head['ny']} = {n} nodes")
    return head, np.concatenate(parts).astype(np.float64) if parts else np.zeros(0)


def _read_ascii(path) -> tuple[dict, np.ndarray]:
    p = Path(path)
    check_memory(p.stat().st_size * 4, path, "the IRAP ASCII surface")
    try:
        text = p.read_text(encoding="ascii")
    except UnicodeDecodeError:
        raise _bad(path, "neither an ASCII nor a binary IRAP file") from None
    try:
        nums = np.array(text.split(), dtype=np.float64)
    except ValueError as err:
        raise _bad(path, f"a value that is not a number ({str(err).split(':')[-1].strip()})") \
            from None
    if nums.size < 19:
        raise _bad(path, f"{nums.size} numbers, fewer than the 19 of the header")
    h = nums[:19]
    head = {"ny": int(h[1]), "xinc": h[2], "yinc": h[3], "xori": h[4], "xmax": h[5],
            "yori": h[6], "ymax": h[7], "nx": int(h[8]), "rotation": h[9]}
    if int(h[0]) != IRAP_ID:
        raise _bad(path, f"it starts with {h[0]:g}, not {IRAP_ID}")
    _check_head(head, path)
    values = nums[19:]
    n = head["nx"] * head["ny"]
    if values.size != n:
        raise _bad(path, f"{values.size} values for {head['nx']}×{head['ny']} = {n} nodes")
    return head, values


def _check_head(head: dict, path) -> None:
    if head["nx"] < 1 or head["ny"] < 1:
        raise _bad(path, f"a grid of {head['nx']}×{head['ny']} nodes")
    for k in ("xinc", "yinc", "xori", "yori", "rotation"):
        if not math.isfinite(head[k]):
            raise _bad(path, f"header {k} is {head[k]}")
    if head["xinc"] <= 0 or head["yinc"] == 0:
        raise _bad(path, f"node spacing {head['xinc']:g} × {head['yinc']:g}")


def read_irap_values(path) -> tuple[dict, np.ndarray]:
    """The header and the ``(ny, nx)`` node values (NaN undefined, row ``j`` = 0 first) of an
    IRAP surface, ASCII or binary (told by its first bytes).

    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "s.fgr")
    >>> _ = open(f, "w").write("-996 2 10 20\\n0 10 0 20\\n2 0 0 0\\n0 0 0 0 0 0 0\\n"
    ...                         "1 2 3 9999900.0\\n")
    >>> head, z = read_irap_values(f)
    >>> head["nx"], head["ny"], z.tolist()
    (2, 2, [[1.0, 2.0], [3.0, nan]])
    """
    p = check_file(path, "an IRAP surface")
    head, v = _read_binary(p) if is_irap_binary(p) else _read_ascii(p)
    z = v.reshape(head["ny"], head["nx"])
    z = np.where((z >= UNDEF * 0.99) | ~np.isfinite(z), np.nan, z)
    return head, z


def read_irap(path, positive: str | None = None) -> Raster:
    """Read an IRAP surface (RMS classic, ASCII or binary) as a terrain raster.

    Parameters
    ----------
    path : path
        ``.gri``, ``.irap``, ``.irapbin`` (binary) or ``.fgr``, ``.irapasc`` (ASCII); the
        content decides.
    positive : {"down", "up"}, optional
        ``down`` (RMS's horizons): the values are depths, heights are ``−value``; ``up``: the
        values are heights. Not given: ``down``, said in ``meta["assumed"]``.

    Returns
    -------
    Raster
        Heights, row 0 south; a rotated surface resampled onto a north-up grid over it
        (``meta["rotated"]``); ``meta``: ``format`` "irap", ``kind`` (ascii/binary),
        ``rotation``, ``nodes`` (nx, ny), ``assumed`` (what the file does not state).

    Raises
    ------
    InputError
        Not an IRAP surface, a damaged header, a truncated file, a count of values that does
        not fit the grid, no defined node.

    Examples
    --------
    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "top.fgr")
    >>> _ = open(f, "w").write("-996 2 10 20\\n100 110 200 220\\n2 0 100 200\\n0 0 0 0 0 0 0\\n"
    ...                         "1500 1510 1490 1505\\n")
    >>> r = read_irap(f)
    >>> r.data.tolist(), r.origin, r.spacing
    ([[-1500.0, -1510.0], [-1490.0, -1505.0]], (95.0, 190.0), (10.0, 20.0))
    """
    told = positive is not None
    positive = "down" if positive is None else positive
    if positive not in ("down", "up"):
        raise InputError(f"positive: expected 'down' (depths) or 'up' (heights), got "
                         f"{positive!r}")
    head, z = read_irap_values(path)
    if not np.isfinite(z).any():
        raise InputError(f"{path}: every node is undefined ({UNDEF:g}); expected a surface")
    kind = "binary" if is_irap_binary(path) else "ascii"
    assumed = ["no length unit in the file, metres assumed"]
    if positive == "down":
        z = -z
        if not told:   # the file does not say; RMS writes depths
            assumed.insert(0, "values are depths (RMS), drawn as height = −depth")
    meta = {"source": str(path), "format": "irap", "kind": kind, "dtype": "float32",
            "rotation": float(head["rotation"]), "nodes": [head["nx"], head["ny"]],
            "geographic": False, "assumed": assumed, "positive": positive,
            "length_unit_assumed": True}
    xinc, yinc, rot = float(head["xinc"]), float(head["yinc"]), float(head["rotation"])
    if yinc < 0:   # rows run south: the same grid with j reversed
        z, yinc = z[::-1], -yinc
        head = {**head, "yori": head["yori"] - (head["ny"] - 1) * yinc * math.cos(
            math.radians(rot)), "xori": head["xori"] + (head["ny"] - 1) * yinc * math.sin(
            math.radians(rot))}
    name = Path(path).name
    if rot % 360 == 0:
        origin = (float(head["xori"]) - xinc / 2, float(head["yori"]) - yinc / 2)
        return Raster(np.ascontiguousarray(z), origin, (xinc, yinc), "", None, name, "", meta)
    from affine import Affine

    # pixel (col, row) of the array with row 0 = the last j (north in the grid's own frame)
    c, s = math.cos(math.radians(rot)), math.sin(math.radians(rot))
    ny = head["ny"]
    top = (head["xori"] - (ny - 1) * yinc * s, head["yori"] + (ny - 1) * yinc * c)
    t = Affine(xinc * c, yinc * s, top[0], xinc * s, -yinc * c, top[1]) @ \
        Affine.translation(-0.5, -0.5)
    data, origin, spacing, note = unrotate(z[::-1], t, "", str(path))
    meta["rotated"] = note
    return Raster(data, origin, spacing, "", None, name, "", meta)


__all__ = ["UNDEF", "is_irap_binary", "read_irap", "read_irap_values"]
