"""Headers of raw volumes: NRRD (``.nhdr`` detached, ``.nrrd`` attached) and MetaImage
(``.mhd`` detached, ``.mha`` attached).

A header gives the shape, value type, byte order, header bytes to skip, voxel size, origin
and (NRRD) the length unit of a raw file; the raw data is then mapped with
:func:`geoshade.io.volumes.raw.read_raw` (never copied).  NRRD headers are read with pynrrd (the
``nrrd`` extra); compressed NRRD data (gzip, bzip2) is decoded by pynrrd into memory.
MetaImage headers are ``Key = Value`` text, parsed here: ``ObjectType``, ``NDims``,
``DimSize``, ``ElementType``, ``ElementSpacing`` (or ``ElementSize``), ``Offset`` (or
``Origin``/``Position``), ``BinaryDataByteOrderMSB``/``ElementByteOrderMSB``, ``HeaderSize``
(``-1``: the data is the end of the file), ``ElementNumberOfChannels``, ``CompressedData``
and ``ElementDataFile`` (a file name, or ``LOCAL`` for data after the header).  MetaImage does
not store a unit; ITK and 3D Slicer read its spacing as millimetres, so the unit is ``mm``
(noted in ``meta["assumed"]``; ``unit=`` overrides it).

:func:`find_sidecar` finds the header beside a raw file (``core.raw`` -> ``core.nhdr``,
``core.mhd``, ``core.raw.nhdr`` ...), used when a raw file is loaded without ``shape``.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError, require
from geoshade.io.paths import check_file, check_memory
from geoshade.io.volumes.raw import RAW_DTYPES, cube_hints, read_raw
from geoshade.models import VoxelVolume

#: suffixes of headers
NRRD_SUFFIXES = (".nhdr", ".nrrd")
MHD_SUFFIXES = (".mhd", ".mha")

#: MetaImage ElementType -> raw dtype name
MET_TYPES = {
    "MET_UCHAR": "uint8", "MET_CHAR": "int8", "MET_USHORT": "uint16", "MET_SHORT": "int16",
    "MET_UINT": "uint32", "MET_INT": "int32", "MET_FLOAT": "float32", "MET_DOUBLE": "float64",
}
#: NRRD type names (all the spellings of the format) -> raw dtype name
NRRD_TYPES = {
    **{k: "int8" for k in ("signed char", "int8", "int8_t")},
    **{k: "uint8" for k in ("uchar", "unsigned char", "uint8", "uint8_t")},
    **{k: "int16" for k in ("short", "short int", "signed short", "signed short int",
                            "int16", "int16_t")},
    **{k: "uint16" for k in ("ushort", "unsigned short", "unsigned short int", "uint16",
                             "uint16_t")},
    **{k: "int32" for k in ("int", "signed int", "int32", "int32_t")},
    **{k: "uint32" for k in ("uint", "unsigned int", "uint32", "uint32_t")},
    "float": "float32", "double": "float64",
}
_UNITS = {"micron": "um", "microns": "um", "micrometer": "um", "micrometre": "um", "µm": "um",
          "millimeter": "mm", "millimetre": "mm", "nanometer": "nm", "meter": "m", "metre": "m"}


def _err(path, field: str, msg: str) -> InputError:
    return InputError(f"{path}: {field}: {msg}")


def _unit(u) -> str:
    u = str(u or "").strip().strip('"')
    return _UNITS.get(u.lower(), u)


# --------------------------------------------------------------------------------------------
# MetaImage
# --------------------------------------------------------------------------------------------
def parse_mhd(path) -> tuple[dict[str, str], int]:
    """The ``Key = Value`` fields of a MetaImage header (keys as written) and, for a ``.mha``
    (``ElementDataFile = LOCAL``), the byte where the data starts.

    Examples
    --------
    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "a.mhd")
    >>> _ = open(f, "w").write("NDims = 3\\nDimSize = 4 3 2\\nElementDataFile = a.raw\\n")
    >>> parse_mhd(f)[0]["DimSize"]
    '4 3 2'
    """
    p = check_file(path, "a MetaImage header")
    fields: dict[str, str] = {}
    start = 0
    with open(p, "rb") as fh:
        for n, raw in enumerate(iter(fh.readline, b"")):
            start += len(raw)
            try:
                line = raw.decode("ascii").strip()
            except UnicodeDecodeError:
                raise _err(path, f"line {n + 1}", "not text; expected 'Key = Value' lines of a "
                           "MetaImage header") from None
            if not line or line.startswith("#"):
                continue
            if "=" not in line:
                raise _err(path, f"line {n + 1}", f"expected 'Key = Value', got {line[:40]!r}")
            key, value = (t.strip() for t in line.split("=", 1))
            fields[key] = value
            if key == "ElementDataFile":  # always the last field; the data may follow
                break
            if n > 200:
                raise _err(path, "header", "no ElementDataFile in the first 200 lines")
    return fields, start


def _numbers(path, fields, key: str, n: int, kind=float, default=None) -> list:
    if key not in fields:
        if default is None:
            raise _err(path, key, f"missing; expected {n} numbers")
        return list(default)
    parts = fields[key].split()
    try:
        vals = [kind(v) for v in parts]
    except ValueError:
        vals = []
    if len(vals) != n:
        raise _err(path, key, f"expected {n} {'integers' if kind is int else 'numbers'}, "
                   f"got {fields[key]!r}")
    return vals


def _bool(path, fields, key: str) -> bool | None:
    v = fields.get(key)
    if v is None:
        return None
    if v.lower() in ("true", "1", "yes"):
        return True
    if v.lower() in ("false", "0", "no"):
        return False
    raise _err(path, key, f"expected True or False, got {v!r}")


def read_mhd(path, spacing=None, unit=None, origin=None) -> VoxelVolume:
    """A MetaImage volume (``.mhd`` + raw file, or ``.mha``), memory-mapped.

    Parameters
    ----------
    path : str or Path
        The ``.mhd``/``.mha`` header.
    spacing, unit, origin : optional
        Override the header's (``unit`` defaults to ``mm``, see the module).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> np.arange(24, dtype=">i2").tofile(os.path.join(d, "a.raw"))
    >>> _ = open(os.path.join(d, "a.mhd"), "w").write(
    ...     "ObjectType = Image\\nNDims = 3\\nDimSize = 4 3 2\\nElementType = MET_SHORT\\n"
    ...     "BinaryDataByteOrderMSB = True\\nElementSpacing = 0.5 0.5 1\\n"
    ...     "ElementDataFile = a.raw\\n")
    >>> v = read_mhd(os.path.join(d, "a.mhd"))
    >>> v.shape_xyz, int(v.data[1, 2, 3]), v.spacing, v.unit
    ((4, 3, 2), 23, (0.5, 0.5, 1.0), 'mm')
    """
    fields, start = parse_mhd(path)
    p = Path(path)
    ot = fields.get("ObjectType", "Image")
    if ot.lower() != "image":
        raise _err(path, "ObjectType", f"expected Image, got {ot!r}")
    ndims = _numbers(path, fields, "NDims", 1, int, default=[3])[0]
    if ndims != 3:
        raise _err(path, "NDims", f"expected a 3D volume (3), got {ndims}")
    shape = _numbers(path, fields, "DimSize", 3, int)
    et = fields.get("ElementType")
    if et is None:
        raise _err(path, "ElementType", "missing; expected one of " + ", ".join(MET_TYPES))
    if et.upper() not in MET_TYPES:
        raise _err(path, "ElementType", f"{et!r} is not supported; expected one of "
                   + ", ".join(MET_TYPES))
    ch = _numbers(path, fields, "ElementNumberOfChannels", 1, int, default=[1])[0]
    if ch != 1:
        raise _err(path, "ElementNumberOfChannels", f"expected 1 (a scalar volume), got {ch}")
    if _bool(path, fields, "CompressedData"):
        raise _err(path, "CompressedData", "compressed MetaImage data is not supported; "
                   "write it uncompressed (e.g. SimpleITK WriteImage(..., useCompression=False))")
    msb = _bool(path, fields, "BinaryDataByteOrderMSB")
    if msb is None:
        msb = _bool(path, fields, "ElementByteOrderMSB")
    sp_key = "ElementSpacing" if "ElementSpacing" in fields else "ElementSize"
    sp = _numbers(path, fields, sp_key, 3, default=[1.0, 1.0, 1.0])
    og_key = next((k for k in ("Offset", "Origin", "Position") if k in fields), "Offset")
    og = _numbers(path, fields, og_key, 3, default=[0.0, 0.0, 0.0])
    tm = fields.get("TransformMatrix")
    if tm is not None:
        m = _numbers(path, fields, "TransformMatrix", 9)
        if not np.allclose(np.abs(m), np.eye(3).ravel()):
            raise _err(path, "TransformMatrix", "rotated volumes are not supported (expected "
                       f"the identity or axis flips), got {tm!r}")
    df = fields.get("ElementDataFile")
    if df is None:
        raise _err(path, "ElementDataFile", "missing; expected the raw file's name or LOCAL")
    if df.upper() == "LIST" or "%" in df or len(df.split()) > 1:
        raise _err(path, "ElementDataFile", f"{df!r}: data split over several files is not "
                   "supported; expected one raw file or LOCAL")
    payload = int(np.prod(shape)) * np.dtype(RAW_DTYPES[MET_TYPES[et.upper()]]).itemsize
    if df.upper() == "LOCAL":
        data_path, offset = p, start
    else:
        data_path = p.parent / df
        hs = _numbers(path, fields, "HeaderSize", 1, int, default=[0])[0]
        if hs == -1:
            try:
                offset = os.path.getsize(data_path) - payload
            except OSError:
                offset = 0  # read_raw names the missing file
            offset = max(offset, 0)
        elif hs < 0:
            raise _err(path, "HeaderSize", f"expected bytes >= 0 or -1, got {hs}")
        else:
            offset = hs
    if not data_path.exists():
        raise _err(path, "ElementDataFile", f"{df!r} does not exist beside the header "
                   f"({data_path})")
    vol = read_raw(data_path, shape, MET_TYPES[et.upper()], endian="big" if msb else "little",
                   spacing=sp if spacing is None else spacing, unit=unit or "mm",
                   offset=offset, origin=og if origin is None else origin)
    meta = {**vol.meta, "format": "mhd", "source": str(path), "data_file": str(data_path)}
    meta.pop("assumed", None)
    if not unit:
        meta["assumed"] = ["unit mm (MetaImage does not store one; ITK reads mm)"]
    return VoxelVolume(vol.data, vol.spacing, vol.origin, vol.unit, name=p.name, meta=meta)


# --------------------------------------------------------------------------------------------
# NRRD
# --------------------------------------------------------------------------------------------
def nrrd_header(path) -> tuple[dict[str, Any], int]:
    """pynrrd's header of a ``.nhdr``/``.nrrd`` and the byte after it (attached data)."""
    nrrd = require("nrrd", "nrrd", "reading NRRD headers")
    p = check_file(path, "an NRRD header")
    with open(p, "rb") as fh:
        head = fh.read(4)
        if head != b"NRRD":
            raise _err(path, "magic", f"expected an NRRD header starting with 'NRRD', got "
                       f"{head!r}")
        fh.seek(0)
        try:
            header = nrrd.read_header(fh)
        except (nrrd.NRRDError, ValueError, UnicodeDecodeError) as exc:
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise _err(path, "header", f"not a valid NRRD header ({first})") from None
        return dict(header), fh.tell()


def _nrrd_spacing(path, h) -> tuple[list[float], list[float] | None]:
    if "spacings" in h:
        sp = [float(v) for v in np.asarray(h["spacings"], float).ravel()]
        return sp, None
    sd = h.get("space directions")
    if sd is None:
        return [1.0, 1.0, 1.0], None
    m = np.asarray(sd, dtype=float)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise _err(path, "space directions", f"expected 3 vectors, got {sd!r}")
    off = m - np.diag(np.diag(m))
    if np.any(np.abs(off) > 1e-9 * np.abs(m).max()):
        raise _err(path, "space directions", "rotated axes are not supported (expected a "
                   "diagonal matrix)")
    return [float(abs(v)) for v in np.diag(m)], None


def read_nhdr(path, spacing=None, unit=None, origin=None) -> VoxelVolume:
    """An NRRD volume: a detached ``.nhdr`` and its raw file, or an attached ``.nrrd``.

    ``raw`` encoding is memory-mapped; ``gzip``/``bzip2`` data is decoded into memory by pynrrd.
    Spacing from ``spacings`` or (diagonal) ``space directions``; origin from ``space origin``;
    unit from ``space units`` (``""`` if absent).

    Examples
    --------
    >>> import tempfile, os, nrrd
    >>> f = os.path.join(tempfile.mkdtemp(), "a.nhdr")
    >>> a = np.arange(24, dtype=np.uint16).reshape(2, 3, 4)
    >>> nrrd.write(f, a, {"encoding": "raw", "spacings": [2.0, 2.0, 3.0],
    ...                   "space units": ["um", "um", "um"]}, detached_header=True,
    ...            index_order="C")
    >>> v = read_nhdr(f)
    >>> v.shape_xyz, v.spacing, v.unit, bool((np.asarray(v.data) == a).all())
    ((4, 3, 2), (2.0, 2.0, 3.0), 'um', True)
    """
    h, start = nrrd_header(path)
    p = Path(path)
    dim = int(h.get("dimension", 0))
    if dim != 3:
        raise _err(path, "dimension", f"expected a 3D volume (3), got {dim}")
    shape = [int(v) for v in np.asarray(h.get("sizes", []), int).ravel()]
    if len(shape) != 3:
        raise _err(path, "sizes", f"expected 3 sizes, got {h.get('sizes')!r}")
    t = str(h.get("type", "")).strip().lower()
    if t not in NRRD_TYPES:
        raise _err(path, "type", f"{t!r} is not supported; expected a scalar integer or float "
                   "type (uchar, short, ushort, int, float, double ...)")
    dtype = NRRD_TYPES[t]
    enc = str(h.get("encoding", "raw")).lower()
    endian = str(h.get("endian", "little")).lower()
    sp, _ = _nrrd_spacing(path, h)
    units = h.get("space units")
    u = _unit(units[0]) if units is not None and len(units) else ""
    og = h.get("space origin")
    og = [0.0, 0.0, 0.0] if og is None else [float(v) for v in np.asarray(og, float).ravel()]
    files = h.get("data file") or h.get("datafile")
    data_path = p if files is None else p.parent / str(files)
    if files is not None and (str(files).upper().startswith("LIST") or "%" in str(files)):
        raise _err(path, "data file", f"{files!r}: data split over several files is not "
                   "supported")
    if not data_path.exists():
        raise _err(path, "data file", f"{files!r} does not exist beside the header "
                   f"({data_path})")
    sp_use = sp if spacing is None else spacing
    og_use = og if origin is None else origin
    unit_use = u if unit is None else unit
    meta: dict[str, Any] = {"format": "nrrd", "source": str(path), "data_file": str(data_path)}
    if enc == "raw":
        payload = int(np.prod(shape)) * np.dtype(RAW_DTYPES[dtype]).itemsize
        skip = int(h.get("byte skip", 0))
        if files is None:  # attached: the data follows the header
            offset = start
        elif skip == -1:
            offset = max(0, os.path.getsize(data_path) - payload)
        else:
            offset = skip
        if int(h.get("line skip", 0)):
            raise _err(path, "line skip", "not supported for raw data; use byte skip")
        vol = read_raw(data_path, shape, dtype, endian=endian, spacing=sp_use, unit=unit_use,
                       offset=offset, origin=og_use)
        meta.update(endian=endian, offset=offset)
        data = vol.data
    elif enc in ("gzip", "gz", "bzip2", "bz2", "ascii", "text", "txt"):

        nrrd = require("nrrd", "nrrd", "reading NRRD data")
        check_memory(int(np.prod(shape)) * np.dtype(RAW_DTYPES[dtype]).itemsize, path,
                     f"decoding {enc} NRRD data")
        try:
            data, _ = nrrd.read(str(p), index_order="C")
        except (nrrd.NRRDError, OSError, ValueError, EOFError) as exc:
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise _err(path, "data", f"cannot be decoded ({first})") from None
        data = np.ascontiguousarray(data)
        meta["encoding"] = enc
    else:
        raise _err(path, "encoding", f"{enc!r} is not supported; expected raw, gzip, bzip2 or "
                   "ascii")
    if not unit_use:   # lengths in voxels, said (the picture, picks and JSON say "assumed")
        meta.setdefault("assumed", []).append("unit voxel (the header has no space units; "
                                              "--unit names one)")
    return VoxelVolume(data, spacing=tuple(np.broadcast_to(np.asarray(sp_use, float), 3)),
                       origin=tuple(np.broadcast_to(np.asarray(og_use, float), 3)),
                       unit=unit_use or "", name=p.name, meta=meta)


# --------------------------------------------------------------------------------------------
# headers beside a raw file
# --------------------------------------------------------------------------------------------
def data_file_of(header) -> Path | None:
    """The raw file a detached header names (None if it cannot be read, or the data follow
    the header in the same file)."""
    header = Path(header)
    try:
        if header.suffix.lower() == ".mhd":
            fields, _ = parse_mhd(header)
            df = fields.get("ElementDataFile")
        else:
            with open(header, "rb") as fh:
                if fh.read(4) != b"NRRD":
                    return None
                fh.seek(0)
                df = None
                for raw in fh.read(1 << 16).split(b"\n"):
                    line = raw.decode("latin-1").strip()
                    if not line:
                        break
                    if line.lower().startswith(("data file:", "datafile:")):
                        df = line.split(":", 1)[1].strip()
    except (InputError, OSError):
        return None
    if not df or str(df).upper() == "LOCAL":
        return None
    return header.parent / df


def find_sidecar(raw_path) -> Path | None:
    """The ``.nhdr``/``.mhd`` beside ``raw_path`` that names it as its data file, or None.

    Looks for ``STEM.nhdr``, ``STEM.mhd``, ``NAME.nhdr`` and ``NAME.mhd`` (``core.raw`` ->
    ``core.nhdr`` ... ``core.raw.mhd``).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> open(os.path.join(d, "c.raw"), "wb").close()
    >>> _ = open(os.path.join(d, "c.mhd"), "w").write("ElementDataFile = c.raw\\n")
    >>> find_sidecar(os.path.join(d, "c.raw")).name
    'c.mhd'
    """
    p = Path(raw_path)
    for stem in (p.with_suffix(""), p):
        for suf in (".nhdr", ".mhd"):
            cand = Path(str(stem) + suf)
            if cand.is_file():
                df = data_file_of(cand)
                if df is not None and df.resolve() == p.resolve():
                    return cand
    return None


def read_raw_hinted(path, shape=None, dtype=None, endian=None, spacing=None, unit=None,
                    offset=None, origin=None) -> VoxelVolume:
    """:func:`~geoshade.io.volumes.raw.read_raw` with what the user did not give found: a
    ``.nhdr``/``.mhd`` header beside the file that names it (:func:`find_sidecar`) when there is
    no ``shape``, else the cube the file size allows (``raw.cube_hints``); the reader of the
    ``raw`` row of :mod:`geoshade.io.formats`."""
    if shape is None:
        side = find_sidecar(path)
        if side is not None:
            if dtype is not None or offset is not None or endian is not None:
                raise InputError(f"{path}: {side.name} beside it gives the shape, dtype, byte "
                                 "order and offset; give them all (--shape ...) to override it, "
                                 "or none")
            vol = read_header_volume(side, spacing=spacing, unit=unit, origin=origin)
            return dataclasses.replace(vol, meta={**vol.meta, "header": str(side)})
    if dtype is None:
        cubes = cube_hints(path, offset or 0)
        fits = f"; its size fits the cube {cubes}" if cubes else ""
        raise InputError(
            f"{path}: headerless raw file and no .nhdr/.mhd header beside it; give --shape NX NY "
            f"NZ and --dtype (the shape may be left out for a cube{fits}), e.g. --shape 110 110 "
            "110 --dtype uint8"
        )
    return read_raw(
        path, shape, dtype, endian=endian or "little", spacing=spacing, unit=unit or "",
        offset=offset or 0, origin=(0.0, 0.0, 0.0) if origin is None else origin,
    )


def read_header_volume(path, **hints) -> VoxelVolume:
    """Read a volume through its header file (NRRD or MetaImage, by suffix)."""
    if Path(path).suffix.lower() in MHD_SUFFIXES:
        return read_mhd(path, **hints)
    return read_nhdr(path, **hints)


__all__ = ["MET_TYPES", "MHD_SUFFIXES", "NRRD_SUFFIXES", "NRRD_TYPES", "data_file_of",
           "find_sidecar", "nrrd_header", "parse_mhd", "read_header_volume", "read_mhd",
           "read_nhdr", "read_raw_hinted"]
