"""TIFF volumes: one multi-page stack, or a folder of 2D slices (via tifffile).

Voxel size comes from the file when it has one:

- ImageJ metadata: ``spacing`` (the z step) and ``unit``;
- ``XResolution``/``YResolution`` tags (pixels per unit, so spacing = 1 / resolution) with
  ``ResolutionUnit`` (or the ImageJ unit);
- OME-XML ``PhysicalSizeX/Y/Z`` and their units.

What is missing is assumed and listed in ``VoxelVolume.meta["assumed"]``.
"""

from __future__ import annotations

import codecs
import itertools
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import tifffile

from geoshade.errors import InputError
from geoshade.models import VoxelVolume

#: suffixes of TIFF files (lower case)
TIFF_SUFFIXES = (".tif", ".tiff")

#: above this many bytes, ``lazy=None`` keeps a volume on disk instead of reading it whole
EAGER_LIMIT_BYTES = 1 << 30

_RESUNIT = {2: "inch", 3: "cm", 4: "mm", 5: "um"}
_UNIT_ALIASES = {
    "micron": "um",
    "µm": "um",
    "μm": "um",
    "microns": "um",
    "pixel": "",
    "pixels": "",
    "micrometer": "um",
    "millimeter": "mm",
    "nanometer": "nm",
}


def _unit(text) -> str:
    s = str(text or "").strip()
    if "\\u" in s:
        try:
            s = codecs.decode(s, "unicode_escape")
        except UnicodeDecodeError:
            pass
    return _UNIT_ALIASES.get(s.lower(), s)


def _open(path) -> tifffile.TiffFile:
    try:
        return tifffile.TiffFile(path)
    except (tifffile.TiffFileError, ValueError, OSError) as err:
        raise InputError(f"{path}: not a readable TIFF file ({err})") from err


def _yx_and_rest(axes: str, shape, path) -> tuple[int, str, int, int]:
    """Check that a series is ``[N]YX`` (dropping length-1 axes); return (N, letter, NY, NX)."""
    kept = [(a, int(n)) for a, n in zip(axes, shape, strict=True) if int(n) > 1 or a in "YX"]
    letters = "".join(a for a, _ in kept)
    desc = f"axes {axes} shape {tuple(int(n) for n in shape)}"
    if "S" in letters:
        raise InputError(
            f"{path}: has colour samples ({desc}); expected grey values, one per voxel"
        )
    if not letters.endswith("YX"):
        raise InputError(f"{path}: expected images with axes Y X last, got {desc}")
    rest, (ny, nx) = kept[:-2], (n for _, n in kept[-2:])
    if not rest:
        return 1, "", ny, nx
    if len(rest) > 1:
        raise InputError(
            f"{path}: expected one stack axis besides Y and X (a 3D volume), got {desc}"
        )
    return rest[0][1], rest[0][0], ny, nx


def _ome_sizes(tf: tifffile.TiffFile) -> dict:
    """PhysicalSize{X,Y,Z} and unit from OME-XML (empty dict if none)."""
    if not tf.is_ome or not tf.ome_metadata:
        return {}
    try:
        root = ET.fromstring(tf.ome_metadata)
    except ET.ParseError:
        return {}
    pix = next((el for el in root.iter() if el.tag.endswith("Pixels")), None)
    if pix is None:
        return {}
    out: dict = {}
    for ax in "XYZ":
        v = pix.get(f"PhysicalSize{ax}")
        if v is not None:
            out[ax.lower()] = float(v)
            out["unit"] = _unit(pix.get(f"PhysicalSize{ax}Unit", "um"))
    return out


def _spacing(tf: tifffile.TiffFile, page) -> tuple[tuple[float, float, float], str, list[str]]:
    """(spacing xyz, unit, assumed notes) from ImageJ, resolution tags or OME metadata."""
    ij = tf.imagej_metadata or {}
    ome = _ome_sizes(tf)
    sx = sy = sz = None
    unit = ""
    tags = page.tags
    res = [tags.get(n) for n in ("XResolution", "YResolution")]
    if all(t is not None for t in res):
        num_den = [t.value for t in res]
        if all(isinstance(v, tuple) and v[0] > 0 and v[1] > 0 for v in num_den):
            sx, sy = (v[1] / v[0] for v in num_den)
            ru = tags.get("ResolutionUnit")
            unit = _RESUNIT.get(int(ru.value) if ru is not None else 2, "")
    if ij:
        if "unit" in ij:
            unit = _unit(ij["unit"])
        if ij.get("spacing") is not None:
            sz = float(ij["spacing"])
    if ome:
        sx, sy = ome.get("x", sx), ome.get("y", sy)
        sz = ome.get("z", sz)
        unit = ome.get("unit", unit)
    assumed = []
    if sx is None:
        sx = sy = 1.0
        assumed.append("x/y spacing 1.0 (no resolution in the file)")
    if sz is None:
        sz = sx
        assumed.append(f"z spacing {sz:g} = x spacing (the file stores no z step)")
    return (float(sx), float(sy), float(sz)), unit, assumed


def _lazy_zarr(make_store, path, required: bool):
    """A lazy array over ``make_store()`` (a tifffile zarr store), or None if tifffile cannot
    serve this file's layout as zarr (the caller then reads eagerly) unless ``required``, which
    raises :class:`InputError`.  A missing or too old zarr is always an error.
    """
    import zarr

    from geoshade.io.zarr_io import as_lazy

    try:
        return as_lazy(zarr.open(make_store(), mode="r"))
    except ImportError as err:
        raise InputError(f"{path}: reading TIFF lazily needs tifffile's zarr support (zarr >= 3, "
                         f"installed {zarr.__version__}): {err}") from None
    except ValueError as err:
        if required:
            raise InputError(
                f"{path}: lazy TIFF reading needs tifffile's zarr support (zarr >= 3, installed "
                f"{zarr.__version__}): {err}; read it with lazy=False"
            ) from err
        return None


def read_tiff(path, lazy: bool | None = None) -> VoxelVolume:
    """Read a multi-page TIFF stack (or one 3D page series) as a :class:`VoxelVolume`.

    Parameters
    ----------
    path : str or Path
        The TIFF file (ImageJ hyperstack, OME-TIFF, plain multi-page).
    lazy : bool, optional
        Uncompressed contiguous files are always memory-mapped (never copied).  Other files
        are read whole when ``lazy`` is False, opened as a lazy zarr/dask array when True, and
        when None (default) read whole only below ``EAGER_LIMIT_BYTES``.

    Returns
    -------
    VoxelVolume
        ``data`` of shape ``(nz, ny, nx)``; spacing and unit from the file when present.

    Raises
    ------
    InputError
        Missing or unreadable file, colour images, a single 2D image, more than 3 dimensions.

    Examples
    --------
    >>> import numpy as np, tempfile, os, tifffile
    >>> f = os.path.join(tempfile.mkdtemp(), "stack.tif")
    >>> a = np.arange(60, dtype=np.uint16).reshape(3, 4, 5)
    >>> tifffile.imwrite(f, a, imagej=True, resolution=(2.0, 2.0),
    ...                  metadata={"spacing": 0.5, "unit": "um", "axes": "ZYX"})
    >>> vol = read_tiff(f)
    >>> vol.shape_xyz, vol.spacing, vol.unit
    ((5, 4, 3), (0.5, 0.5, 0.5), 'um')
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    if p.is_dir():
        raise InputError(
            f"{path}: is a folder; expected a TIFF file (read_tiff_folder reads slices)"
        )
    tf = _open(p)
    keep_open = False
    try:
        if not tf.series:
            raise InputError(f"{path}: TIFF file holds no images")
        series = tf.series[0]
        nz, zaxis, ny, nx = _yx_and_rest(series.axes, series.shape, path)
        if zaxis == "":
            raise InputError(
                f"{path}: holds a single 2D image ({nx}×{ny}); expected a 3D stack "
                "(several pages), or pass the folder of slices"
            )
        spacing, unit, assumed = _spacing(tf, series.pages[0] if series.pages else tf.pages[0])
        meta: dict = {"format": "tiff", "source": str(path), "axes": series.axes}
        if zaxis != "Z":
            assumed.append(f"stack axis {zaxis!r} of {series.axes} taken as z")
        if len(tf.series) > 1:
            meta["note"] = f"file has {len(tf.series)} image series; read the first"
        dtype = np.dtype(series.dtype)
        shape = (nz, ny, nx)
        data = None
        if series.dataoffset is not None:
            try:
                data = tifffile.memmap(p, series=0, mode="r").reshape(shape)
                meta["storage"] = "memmap"
            except (ValueError, TypeError):
                data = None
        if data is None:
            big = nz * ny * nx * dtype.itemsize > EAGER_LIMIT_BYTES
            if (lazy or (lazy is None and big)) and len(series.shape) == 3:
                data = _lazy_zarr(series.aszarr, path, required=bool(lazy))
                keep_open = data is not None
                meta["storage"] = "lazy"
            if data is None:
                data = series.asarray().reshape(shape)
                meta["storage"] = "memory"
        if assumed:
            meta["assumed"] = assumed
        return VoxelVolume(data=data, spacing=spacing, unit=unit, name=p.name, meta=meta)
    finally:
        if not keep_open:
            tf.close()


_DIGITS = re.compile(r"(\d+)")


def _slice_number(path: Path) -> int | None:
    found = _DIGITS.findall(path.stem)
    return int(found[-1]) if found else None


def _natural_key(path: Path):
    return [int(t) if t.isdigit() else t.lower() for t in _DIGITS.split(path.name)]


def list_slices(folder) -> list[Path]:
    """The TIFF slices of a folder in stack order, checked for gaps.

    Files are ordered by the last number in their name (``scan_0002.tif`` before
    ``scan_0010.tif``); the numbers must be consecutive.

    Raises
    ------
    InputError
        No TIFF files, a file without a number, two files with the same number, or a gap.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> for i in (10, 9, 11):
    ...     _ = (d / f"s_{i}.tif").write_bytes(b"")
    >>> [p.name for p in list_slices(d)]
    ['s_9.tif', 's_10.tif', 's_11.tif']
    """
    d = Path(folder)
    if not d.is_dir():
        raise InputError(f"{folder}: no such folder")
    files = [
        f
        for f in d.iterdir()
        if f.is_file() and f.suffix.lower() in TIFF_SUFFIXES and not f.name.startswith(".")
    ]
    if not files:
        raise InputError(f"{folder}: no .tif/.tiff slices in this folder")
    files.sort(key=_natural_key)
    if len(files) == 1:
        return files
    numbered = []
    for f in files:
        n = _slice_number(f)
        if n is None:
            raise InputError(
                f"{f}: slice file name has no number; expected names such as slice_0001.tif "
                "so that the slices can be ordered"
            )
        numbered.append((n, f))
    numbered.sort(key=lambda t: (t[0], _natural_key(t[1])))
    for (n0, f0), (n1, f1) in itertools.pairwise(numbered):
        if n1 == n0:
            raise InputError(f"{folder}: slices {f0.name} and {f1.name} have the same number {n0}")
        if n1 != n0 + 1:
            miss = f"{n0 + 1}" if n1 == n0 + 2 else f"{n0 + 1}..{n1 - 1}"
            raise InputError(
                f"{folder}: slice numbers jump from {n0} ({f0.name}) to {n1} ({f1.name}); "
                f"slice {miss} is missing"
            )
    return [f for _, f in numbered]


def _slice_info(f: Path) -> tuple[int, int, np.dtype]:
    with _open(f) as tf:
        if not tf.series:
            raise InputError(f"{f}: TIFF file holds no images")
        s = tf.series[0]
        n, _, ny, nx = _yx_and_rest(s.axes, s.shape, f)
        if n != 1:
            raise InputError(f"{f}: expected one 2D slice, got a stack of {n} images")
        return ny, nx, np.dtype(s.dtype)


def read_tiff_folder(folder, lazy: bool | None = None) -> VoxelVolume:
    """Read a folder of 2D TIFF slices (one per z) as a :class:`VoxelVolume`.

    Parameters
    ----------
    folder : str or Path
        Folder of ``*.tif``/``*.tiff`` slices, ordered by the last number in their names.
    lazy : bool, optional
        False: read all slices into one numpy array; True: a lazy zarr/dask array that reads
        slices on demand; None (default): lazy only above ``EAGER_LIMIT_BYTES``.

    Returns
    -------
    VoxelVolume
        ``data`` of shape ``(nslices, ny, nx)``; spacing from the first slice's metadata.

    Raises
    ------
    InputError
        Missing folder, no slices, gaps in the numbering, or a slice whose size or dtype
        differs from the first one (the message names that slice).

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib, tifffile
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> for z in range(3):
    ...     tifffile.imwrite(d / f"slice_{z:03d}.tif", np.full((4, 5), z, np.uint8))
    >>> vol = read_tiff_folder(d)
    >>> vol.shape_xyz, int(vol.data[2, 0, 0])
    ((5, 4, 3), 2)
    """
    files = list_slices(folder)
    ny, nx, dtype = _slice_info(files[0])
    for f in files[1:]:
        fy, fx, fdt = _slice_info(f)
        if (fy, fx) != (ny, nx) or fdt.name != dtype.name:
            raise InputError(
                f"{f}: slice is {fx}×{fy} {fdt.name} but the first slice {files[0].name} is "
                f"{nx}×{ny} {dtype.name}; expected all slices alike"
            )
    nz = len(files)
    with _open(files[0]) as tf:
        spacing, unit, assumed = _spacing(tf, tf.pages[0])
    meta: dict = {
        "format": "tiff-folder",
        "source": str(folder),
        "slices": nz,
        "first": files[0].name,
        "last": files[-1].name,
    }
    big = nz * ny * nx * dtype.itemsize > EAGER_LIMIT_BYTES
    data = None
    if lazy or (lazy is None and big):
        seq = tifffile.TiffSequence([str(f) for f in files])
        data = _lazy_zarr(seq.aszarr, folder, required=bool(lazy))
    if data is not None:
        if tuple(data.shape) != (nz, ny, nx):
            raise InputError(
                f"{folder}: slices read as shape {tuple(data.shape)}, expected {(nz, ny, nx)}"
            )
        meta["storage"] = "lazy"
    else:
        data = np.empty((nz, ny, nx), dtype=dtype.newbyteorder("="))
        for z, f in enumerate(files):
            data[z] = tifffile.imread(f).reshape(ny, nx)
        meta["storage"] = "memory"
    if assumed:
        meta["assumed"] = assumed
    return VoxelVolume(data=data, spacing=spacing, unit=unit, name=Path(folder).name, meta=meta)
