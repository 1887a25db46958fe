"""TIFF volumes: one multi-page stack, or a folder of 2D slices (via tifffile).

Voxel size comes from the file when it has one:

- ImageJ metadata: ``spacing`` (the z step) and ``unit``;
- ``XResolution``/``YResolution`` tags (pixels per unit, so spacing = 1 / resolution) with
  ``ResolutionUnit`` (or the ImageJ unit);
- OME-XML ``PhysicalSizeX/Y/Z`` and their units.

A *print* resolution is not a voxel size: a resolution in pixels per inch (TIFF's default unit,
which image programs fill with 72, 96, 100 or 300 dpi, and which ImageJ copies into its own
``unit=inch``), or in pixels per centimetre that is a round number of dots per inch
(:data:`PRINT_DPI`), without OME sizes, gives spacing 1 and no length unit, both assumed, and
``meta["print_resolution"]`` keeps what the file said (``--spacing``/``--unit`` give the real
voxel size).

What is missing is assumed and listed in ``VoxelVolume.meta["assumed"]`` (a volume without a
length unit: "unit voxel").

Damaged files (issue 12) are one line, never tifffile's log lines or a traceback: tifffile logs a
broken page list (a truncated file) through ``logging``; those records are kept
(:func:`geoshade.io.paths.captured_logs`) and turned into the error; every page's data must lie
inside the file; decoding errors (a corrupt compressed strip), also in lazy reads, name the file;
an eager read checks the available memory first.
"""

from __future__ import annotations

import codecs
import contextlib
import itertools
import logging
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import tifffile

from geoshade.errors import GeoshadeError, InputError
from geoshade.io.paths import captured_logs, check_file, check_folder, check_memory, one_line
from geoshade.models import VoxelVolume

#: suffixes of TIFF files (lower case)
TIFF_SUFFIXES = (".tif", ".tiff")

#: above this many bytes, ``lazy=None`` keeps a volume on disk instead of reading it whole
EAGER_LIMIT_BYTES = 1 << 30

_RESUNIT = {2: "inch", 3: "cm", 4: "mm", 5: "um"}
#: dots per inch of printers and screens: a resolution of these (per inch, or per cm as their
#: metric equivalent) is a print resolution, not a voxel size
PRINT_DPI = (72, 75, 96, 100, 120, 150, 200, 240, 300, 400, 600, 1200, 2400)
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


#: tifffile log messages that mean the file itself is damaged (truncated, broken page list)
_DAMAGE = re.compile(
    r"invalid (page offset|offset to (first )?page|circular reference|next page|value offset)"
    r"|corrupted|incorrect Strip|missing data|failed to read|is missing \d+|missing \d+ pages"
    r"|incompletely written|Missing data are zeroed", re.IGNORECASE)


def _log_text(record: logging.LogRecord) -> str:
    msg = record.getMessage()
    return re.sub(r"^<tifffile\.[^>]*>\s*", "", msg).strip()


def _raise_damage(records, path) -> None:
    """An error for the first record that says the file is damaged, if any."""
    for r in records:
        if _DAMAGE.search(r.getMessage()):
            size = _size(path)
            raise InputError(f"{path}: damaged TIFF file, probably truncated ({size} bytes): "
                             f"{_log_text(r)}")


def _size(path) -> int | str:
    try:
        return os.path.getsize(path)
    except OSError:
        return "?"


@contextlib.contextmanager
def _reading(path) -> Iterator[list]:
    """Silence tifffile's log lines while reading ``path``; a damage record, a decoding error or
    a library error becomes one line naming the file."""
    with captured_logs("tifffile") as records:
        try:
            yield records
        except Exception as err:  # tifffile and its codecs raise many types
            _raise_damage(records, path)  # the cause, rather than what followed from it
            if isinstance(err, GeoshadeError | MemoryError):
                raise
            raise InputError(f"{path}: damaged TIFF image data ({one_line(err)})") from None
        _raise_damage(records, path)


def _open(path) -> tifffile.TiffFile:
    check_file(path, "a TIFF file")
    with captured_logs("tifffile") as records:
        try:
            tf = tifffile.TiffFile(path)
        except (tifffile.TiffFileError, ValueError, OSError, EOFError) as err:
            _raise_damage(records, path)
            raise InputError(f"{path}: not a readable TIFF file ({one_line(err)})") from None
    return tf


def _check_pages(series, path) -> None:
    """Every page's data must lie inside the file (a truncated stack is refused, not read as
    zeros or as fewer pages)."""
    size = os.path.getsize(path)
    if series.dataoffset is not None:  # contiguous: one range, no page needs reading
        end = int(series.dataoffset) + int(series.nbytes)
        if end > size:
            raise InputError(f"{path}: truncated TIFF file: its image data need bytes up to "
                             f"{end} but the file has {size}")
        return
    pages = series.pages
    for i, page in enumerate(pages):
        if page is None:
            continue
        ends = [int(o) + int(c) for o, c in zip(page.dataoffsets, page.databytecounts,
                                                 strict=False)]
        if ends and max(ends) > size:
            raise InputError(f"{path}: truncated TIFF file: page {i + 1} of {len(pages)} needs "
                             f"bytes up to {max(ends)} but the file has {size}")


class _CheckedTiff:
    """A lazy TIFF array whose reads turn decoding errors into one line (dask reads it); for a
    folder of slices (``files``) the line names the damaged slice."""

    def __init__(self, arr, path, files=None):
        self.arr, self.path, self.files = arr, str(path), files
        self.shape, self.dtype = tuple(arr.shape), np.dtype(arr.dtype)
        self.ndim = len(self.shape)
        self.chunks = tuple(int(c) for c in arr.chunks)

    def __getitem__(self, key):
        try:
            with _reading(self.path):
                return np.asarray(self.arr[key])
        except InputError:
            if self.files:
                z = key[0] if isinstance(key, tuple) else key
                zs = range(*z.indices(len(self.files))) if isinstance(z, slice) else [int(z)]
                for i in zs:  # which slice: read them one by one
                    with _reading(self.files[i]):
                        tifffile.imread(self.files[i])
            raise


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


def print_resolution(unit: str, sx: float, sy: float) -> str | None:
    """``"100 pixels/inch"`` where ``(sx, sy)`` (spacing in ``unit``) is a print resolution
    (see the module), else None.

    >>> print_resolution("inch", 0.01, 0.01), print_resolution("cm", 1 / 39.37, 1 / 39.37)
    ('100 pixels/inch', '39.37 pixels/cm (100 dpi)')
    >>> print_resolution("cm", 0.25, 0.25) is None, print_resolution("um", 1.0, 1.0) is None
    (True, True)
    """
    if unit not in ("inch", "cm") or sx <= 0 or sy <= 0:
        return None
    px = 1.0 / sx
    per = f"{px:.4g} pixels/{unit}" if sx == sy else f"{px:.4g}×{1 / sy:.4g} pixels/{unit}"
    if unit == "inch":
        return per
    dpi = px * 2.54
    near = min(PRINT_DPI, key=lambda d: abs(d - dpi))
    return f"{per} ({near} dpi)" if abs(dpi - near) <= 0.01 * near else None


def _spacing(tf: tifffile.TiffFile, page) -> tuple[tuple[float, float, float], str, list[str],
                                                  dict]:
    """(spacing xyz, unit, assumed notes, extra meta) from ImageJ, resolution tags or OME
    metadata (a print resolution is not a voxel size: see the module)."""
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
    assumed, extra = [], {}
    printed = None if ome or sx is None else print_resolution(unit, sx, sy)
    if printed is not None:   # a print resolution: no voxel size in the file
        extra["print_resolution"] = printed
        assumed.append(f"spacing 1.0 (the file's {printed} is a print resolution, not a voxel "
                       "size; --spacing gives one)")
        sx = sy = 1.0
        sz, unit = None, ""
    if ome:
        sx, sy = ome.get("x", sx), ome.get("y", sy)
        sz = ome.get("z", sz)
        unit = ome.get("unit", unit)
    if sx is None:
        sx = sy = 1.0
        assumed.append("x/y spacing 1.0 (no resolution in the file)")
    if sz is None:
        sz = sx
        if printed is None:
            assumed.append(f"z spacing {sz:g} = x spacing (the file stores no z step)")
    if not unit:
        assumed.append("unit voxel (the file names no length unit; --unit names one)")
    return (float(sx), float(sy), float(sz)), unit, assumed, extra


def _lazy_zarr(make_store, path, required: bool, files=None):
    """A lazy array over ``make_store()`` (a tifffile zarr store), or None if tifffile cannot
    serve this file's layout as zarr (the caller then reads eagerly) unless ``required``, which
    raises :class:`InputError`.  A missing or too old zarr is always an error.
    """
    import zarr

    try:
        arr = zarr.open(make_store(), mode="r")
        view = _CheckedTiff(arr, path, files)
        import dask.array as da
        from dask.base import tokenize

        st = os.stat(path)
        name = "tiff-" + tokenize(os.path.abspath(path), st.st_mtime_ns, st.st_size, view.shape)
        return da.from_array(view, chunks=view.chunks, asarray=True, fancy=False, lock=False,
                             name=name, meta=np.empty((0,) * view.ndim, view.dtype))
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
    tf = _open(p)
    keep_open = False
    try:
        with _reading(path):
            if not tf.series:
                raise InputError(f"{path}: TIFF file holds no images")
            series = tf.series[0]
            nz, zaxis, ny, nx = _yx_and_rest(series.axes, series.shape, path)
            _check_pages(series, path)
            if zaxis == "":
                raise InputError(
                    f"{path}: holds a single 2D image ({nx}×{ny}); expected a 3D stack "
                    "(several pages), or pass the folder of slices"
                )
            spacing, unit, assumed, extra = _spacing(tf, series.pages[0] if series.pages
                                                     else tf.pages[0])
        meta: dict = {"format": "tiff", "source": str(path), "axes": series.axes, **extra}
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
                check_memory(nz * ny * nx * dtype.itemsize, path, f"the {nx}×{ny}×{nz} "
                             f"{dtype.name} stack", "read it lazily (lazy=True)")
                with _reading(path):
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
    if not d.exists():
        raise InputError(f"{folder}: no such folder")
    check_folder(d, "a folder of TIFF slices")
    files = [
        f for f in d.iterdir() if f.suffix.lower() in TIFF_SUFFIXES and not f.name.startswith(".")
    ]
    for f in files:  # a FIFO, device or folder named like a slice is refused, not skipped
        check_file(f, "a TIFF slice (a file)")
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
    with _open(f) as tf, _reading(f):
        if not tf.series:
            raise InputError(f"{f}: TIFF file holds no images")
        s = tf.series[0]
        n, _, ny, nx = _yx_and_rest(s.axes, s.shape, f)
        if n != 1:
            raise InputError(f"{f}: expected one 2D slice, got a stack of {n} images")
        _check_pages(s, f)
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
    with _open(files[0]) as tf, _reading(files[0]):
        spacing, unit, assumed, extra = _spacing(tf, tf.pages[0])
    meta: dict = {
        **extra,
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
        data = _lazy_zarr(seq.aszarr, folder, required=bool(lazy), files=files)
    if data is not None:
        if tuple(data.shape) != (nz, ny, nx):
            raise InputError(
                f"{folder}: slices read as shape {tuple(data.shape)}, expected {(nz, ny, nx)}"
            )
        meta["storage"] = "lazy"
    else:
        check_memory(nz * ny * nx * dtype.itemsize, folder, f"{nz} slices of {nx}×{ny} "
                     f"{dtype.name}", "read them lazily (lazy=True)")
        data = np.empty((nz, ny, nx), dtype=dtype.newbyteorder("="))
        for z, f in enumerate(files):
            with _reading(f):
                data[z] = tifffile.imread(f).reshape(ny, nx)
        meta["storage"] = "memory"
    if assumed:
        meta["assumed"] = assumed
    return VoxelVolume(data=data, spacing=spacing, unit=unit, name=Path(folder).name, meta=meta)
