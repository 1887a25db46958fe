"""Zarr volumes (zarr-python 2.17+ and 3.x): chunked, compressed, read lazily.

A store holds one 3D array ``(nz, ny, nx)``, either at its root or inside a group as
``data`` or ``0`` (level 0 of a multiscale pyramid, as OME-Zarr writes it).  Attributes, on the
array or its group:

- ``spacing``: ``[sx, sy, sz]`` voxel size (x, y, z)
- ``unit``: length unit of ``spacing`` and ``origin``
- ``origin``: ``[x0, y0, z0]`` position of the first voxel's corner

OME-Zarr ``multiscales`` metadata (:mod:`geoshade.io.stores.ome_zarr`: NGFF 0.5 under ``"ome"``, 0.4
and older at the top; axes, ``scale`` and ``translation``) name the levels and give the spacing,
origin and unit when those attributes are absent; axes other than z, y, x (``t``, ``c``) must
hold one element.  Stores written by :func:`geoshade.io.stores.ingest.ingest` are OME-Zarr 0.5
multiscale images that keep geoshade's attributes.

Damaged stores (issue 12): every read goes through :class:`geoshade.io.stores.chunks.StoreArray`,
which
checks each chunk it touches against the CRC-32 geoshade recorded when it wrote the store (a
missing chunk is an error, never zeros); opening checks that the arrays' metadata are the ones
written and that an ingest finished; :func:`verify_store` (``geoshade core verify``) checks every
chunk of every level.  Every zarr, codec or JSON error is one line naming the store and the array
or chunk.
"""

from __future__ import annotations

import json
import os
import shutil
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import check_replace, publish
from geoshade.io.paths import check_folder, one_line
from geoshade.io.stores.chunks import (
    ALGORITHM,
    DamagedStoreError,
    StoreArray,
    check_record,
    checksum_record,
    chunk_crcs,
)
from geoshade.io.stores.ome_zarr import Multiscale, multiscales_attrs, parse_multiscales
from geoshade.io.volumes.raw import as_xyz
from geoshade.models import VoxelVolume
from geoshade.progress import Progress

#: files that mark a folder as a zarr store (v3, v2 array, v2 group)
ZARR_MARKERS = ("zarr.json", ".zarray", ".zgroup")

#: names of the array inside a group, tried in this order
ARRAY_NAMES = ("data", "0")

#: bytes per slab when copying a volume into a store
SLAB_BYTES = 64 << 20


def is_zarr_store(path) -> bool:
    """True if ``path`` is a folder named ``*.zarr`` or holding zarr metadata.

    Examples
    --------
    >>> is_zarr_store("no/such/folder")
    False
    """
    p = Path(path)
    if not p.is_dir():
        return False
    return p.suffix.lower() == ".zarr" or any((p / m).exists() for m in ZARR_MARKERS)


def as_lazy(array) -> Any:
    """A dask array over ``array`` (a zarr array, or anything ``dask.array.from_array`` takes).

    Examples
    --------
    >>> import numpy as np
    >>> as_lazy(np.zeros((2, 2, 2))).shape
    (2, 2, 2)
    """
    import dask.array as da
    import zarr

    if isinstance(array, zarr.Array):
        return da.from_zarr(array)
    return da.from_array(array)


def _check_metadata_depth(folder: Path) -> None:
    """Refuse metadata nested too deeply for Python's JSON reader (100,000 nested ``[`` in a
    400-byte-per-level zarr.json) before zarr parses it in its own thread."""

    for m in ZARR_MARKERS:
        f = folder / m
        if (f.exists() or f.is_symlink()) and not f.is_file():   # a FIFO would block the read
            raise InputError(f"{f}: not a regular file (a FIFO, a device or a folder), so not "
                             "zarr metadata")
        try:
            if not f.is_file() or f.stat().st_size > (64 << 20):
                continue
            json.loads(f.read_bytes())
        except RecursionError:
            raise InputError(f"{f}: metadata JSON nested too deeply (crafted or damaged)"
                             ) from None
        except (OSError, ValueError):
            continue  # zarr says what is wrong


def _open(path):
    """The zarr node at ``path`` (a folder), or one line saying why not."""
    import zarr

    p = check_folder(path, "a zarr store (a folder)")
    if not any((p / m).exists() for m in ZARR_MARKERS):
        raise InputError(f"{path}: not a readable zarr store: no zarr.json, .zarray or .zgroup "
                         "in the folder (its metadata are missing)")
    _check_metadata_depth(p)
    try:
        return zarr.open(str(path), mode="r")
    except Exception as err:  # zarr raises many kinds; one line for the user
        raise InputError(f"{path}: not a readable zarr store ({one_line(err)})") from None


def _zarr_step(path, where: str, fn):
    """``fn()``, with any zarr/codec/JSON error turned into one line naming the store and
    ``where`` (an array or attribute)."""
    try:
        return fn()
    except InputError:
        raise
    except MemoryError:
        raise
    except Exception as err:
        raise DamagedStoreError(f"{path}: {where}: cannot be read ({one_line(err)})") from None


def _store_array(arr, path, where: str, crcs) -> StoreArray:
    """The checking view of ``arr`` (a zarr array of the store at ``path``)."""
    sp = arr.store_path
    root = getattr(sp.store, "root", None)
    if root is None:  # not a local folder (zarr_io only opens folders)
        raise InputError(f"{path}: {where}: expected a zarr store in a local folder")
    return StoreArray(root, sp.path, str(path), crcs=crcs, arr=arr)


#: at most this many declared chunk keys are probed one by one (a 400-byte zarr.json can declare
#: billions); beyond, stored chunks are counted by listing the array's folder
PROBE_CHUNKS = 100_000
_METADATA = frozenset({"zarr.json", ".zarray", ".zattrs", ".zgroup", ".zmetadata"})


def _count_stored_chunks(folder: Path | None, total: int) -> int | None:
    """Chunk files under an array's ``folder``, found by listing it (what is stored, however
    many chunks the metadata declare); None when it cannot be listed. Sub-folders that are
    arrays or groups of their own are not counted."""
    if folder is None or not folder.is_dir():
        return None
    n = 0
    try:
        for top, dirs, files in os.walk(folder):
            if Path(top) != folder and _METADATA.intersection(files):
                dirs[:] = []
                continue
            n += sum(1 for f in files if f not in _METADATA and not f.startswith("."))
            if n > total:
                break
    except OSError:
        return None
    return n


def _missing_note(arr, view: StoreArray, meta: dict | None = None) -> str | None:
    """For a store geoshade did not write: how many chunks are not stored (read as the fill
    value by zarr's rule), or None when all are; ``meta["chunks_stored"]`` gets ``[stored,
    declared]`` where they were counted (a count over a box refuses what would read mostly fill
    values: :func:`geoshade.core.porosity`)."""
    if getattr(arr, "shards", None) is not None:
        return None
    total = int(np.prod(view.grid))
    stored = _count_stored_chunks(Path(view.root) / view.path, total)
    if stored is None:
        try:  # zarr probes every declared chunk key: only where there are few
            stored = int(arr.nchunks_initialized) if total <= PROBE_CHUNKS else None
        except Exception:  # listing not supported: say nothing
            stored = None
    if stored is None:
        return None
    if meta is not None:
        meta["chunks_stored"] = [int(stored), int(total)]
    if stored >= total:
        return None
    fill = getattr(arr.fill_value, "item", lambda: arr.fill_value)()
    return (f"{total - stored} of {total} chunks are not stored and read as the fill value "
            f"{fill!r} (zarr's rule for chunks never written; this store carries no "
            "geoshade checksums, so a lost chunk cannot be told from an empty one)")


def _check_complete(attrs: dict, path) -> dict | None:
    """Refuse a store whose ``ingest`` attribute says it is unfinished (geoshade.io.stores.ingest);
    return that attribute (None: the store was not ingested)."""
    ing = attrs.get("ingest")
    if ing is None:
        return None
    if not isinstance(ing, dict):
        raise DamagedStoreError(f"{path}: zarr.json: the 'ingest' attribute is damaged (expected "
                                f"an object, got {type(ing).__name__})")
    if ing.get("complete", False) is not True:
        raise InputError(
            f"{path}: incomplete store (its ingest was interrupted or is still running; "
            "ingest.complete is false); run the same 'geoshade core ingest' again to finish it"
        )
    return ing


def _check_group_record(ing: dict | None, crcs, path, where: str) -> None:
    """A level written with checksums needs the group's ingest record, and the other way."""
    if crcs is not None and ing is None:
        raise DamagedStoreError(
            f"{path}: zarr.json: the group has lost its ingest record (its array {where} "
            "carries geoshade checksums); the group metadata are damaged: ingest the store again")
    if crcs is None and ing is not None and ing.get("checksums") == ALGORITHM:
        raise DamagedStoreError(
            f"{path}: array {where}: its checksum record is missing although the ingest wrote "
            "one; its zarr.json was replaced or damaged: ingest the store again")


def read_zarr(path) -> VoxelVolume:
    """Open a zarr store as a lazy :class:`VoxelVolume`.

    Parameters
    ----------
    path : str or Path
        A zarr folder: an array, or a group holding an array named ``data`` or ``0``.

    Returns
    -------
    VoxelVolume
        ``data`` is a dask array when dask is installed, else the zarr array (nothing is read
        until it is sliced).  Missing ``spacing``/``origin`` are taken as 1.0 / 0.0 and listed in
        ``meta["assumed"]``.

    Raises
    ------
    InputError
        Not a store, no suitable array, not 3D, or bad attributes.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.models import VoxelVolume
    >>> f = os.path.join(tempfile.mkdtemp(), "v.zarr")
    >>> _ = write_zarr(VoxelVolume(np.ones((2, 3, 4), np.uint8), spacing=(2, 2, 2)), f)
    >>> vol = read_zarr(f)
    >>> vol.shape_xyz, vol.spacing
    ((4, 3, 2), (2.0, 2.0, 2.0))
    """
    p = Path(path)
    node = _open(p)
    arr, where, attrs, ing, ms = _pick_array(node, path)
    crcs = check_record(arr, path, where)
    if hasattr(node, "array_keys"):
        _check_group_record(ing, crcs, path, where)
    index = _space_index(ms, arr, path, 0 if ms is not None and where == ms.paths[0] else None)
    shape = tuple(int(n) for i, n in zip(index, arr.shape, strict=False) if not isinstance(i, int))
    if len(shape) != 3:
        raise InputError(
            f"{path}{'/' + where if where else ''}: expected a 3D array (nz, ny, nx), got shape "
            f"{tuple(int(n) for n in arr.shape)}"
        )
    view = _store_array(arr, path, where, crcs)
    chunks = tuple(int(c) for i, c in zip(index, arr.chunks, strict=False)
                   if not isinstance(i, int))
    meta: dict = {"format": "zarr", "source": str(path), "chunks": chunks,
                  "checksums": ALGORITHM if crcs is not None else None}
    if ms is not None:
        meta["levels"] = len(ms.paths)
        meta["ngff"] = ms.version or ""
    if attrs.get("labels") is True:  # written by write_zarr(labels=True): a segmentation
        meta["labels"] = True
    assumed = []
    try:
        if attrs.get("spacing") is not None:
            spacing = as_xyz(attrs["spacing"], "spacing attribute", path)
        else:
            spacing = (1.0, 1.0, 1.0)
            assumed.append("spacing 1.0 (no 'spacing' attribute)")
        if attrs.get("origin") is not None:
            origin = as_xyz(attrs["origin"], "origin attribute", path, positive=False)
        else:
            origin = (0.0, 0.0, 0.0)
            assumed.append("origin 0.0 (no 'origin' attribute)")
        vr = attrs.get("value_range")
        if vr is not None:  # written by geoshade.io.stores.ingest
            if not (isinstance(vr, list) and len(vr) == 2
                    and all(isinstance(v, int | float) for v in vr)):
                raise ValueError(f"value_range: expected [min, max], got {vr!r}")
            meta["value_range"] = list(vr)
    except (TypeError, ValueError) as err:
        raise DamagedStoreError(f"{path}: zarr.json: damaged attributes ({one_line(err)})"
                                ) from None
    if crcs is None:
        note = _missing_note(arr, view, meta)
        if note:
            assumed.append(note)
    if assumed:
        meta["assumed"] = assumed
    unit = str(attrs.get("unit") or "")
    data = view.as_dask()
    if any(isinstance(i, int) for i in index):
        data = data[index]  # the single time point / channel: a lazy 3D view
    return VoxelVolume(
        data=data, spacing=spacing, origin=origin, unit=unit, name=p.name, meta=meta
    )


def _space_index(ms: Multiscale | None, arr, path, level: int | None) -> tuple:
    """The index of ``arr`` that gives its (nz, ny, nx) view: from the ``multiscales`` axes
    when ``arr`` is one of their levels, else the whole array."""
    if ms is None or level is None:
        return (slice(None),) * len(arr.shape)
    return ms.index(arr.shape, path, level)


def _pick_array(node, path):
    """(array, its path in the store, merged attributes, the group's ingest record or None,
    the group's checked ``multiscales`` or None)."""
    if not hasattr(node, "array_keys"):  # the store is one array
        return node, "", _zarr_step(path, "zarr.json", lambda: dict(node.attrs)), None, None
    gattrs = _zarr_step(path, "zarr.json", lambda: dict(node.attrs))
    ing = _check_complete(gattrs, path)  # issue 6: refuse an unfinished `geoshade core ingest`
    ms = parse_multiscales(gattrs, path)
    ome: dict = {}
    if ms is not None:
        ome = {"spacing": ms.spacing(0), "origin": ms.origin(0), "unit": ms.unit or None}
        ome = {k: v for k, v in ome.items() if v is not None}
    sub = ms.paths[0] if ms is not None else ""
    names = ([sub] if sub else []) + list(ARRAY_NAMES)
    name = next((n for n in names if (Path(path) / n).is_dir()), None)
    if name is None:
        keys = _zarr_step(path, "the group's arrays", lambda: list(node.array_keys()))
        why = ("" if ms is not None else " and no OME-Zarr 'multiscales' attribute naming "
               "its levels")
        raise InputError(
            f"{path}: zarr group has no array named {' or '.join(repr(n) for n in names)}{why}; "
            f"it holds arrays {keys or 'none'}"
        )
    arr = _zarr_step(path, f"array {name}", lambda: node[name])
    if not hasattr(arr, "dtype"):
        raise InputError(f"{path}: {name} is a zarr group; expected the volume's array there")
    aattrs = _zarr_step(path, f"array {name}", lambda: dict(arr.attrs))
    aattrs.pop("checksums", None)
    return arr, name, {**ome, **gattrs, **aattrs}, ing, ms


def _chunks(chunks, shape) -> tuple[int, int, int]:
    try:
        c = [int(v) for v in chunks]
    except (TypeError, ValueError):
        c = []
    if len(c) != 3 or min(c) < 1:
        raise InputError(f"chunks: expected 3 positive integers (cz, cy, cx), got {chunks!r}")
    return tuple(min(a, int(n)) for a, n in zip(c, shape, strict=True))


def write_zarr(volume: VoxelVolume, path, chunks=(64, 64, 64), overwrite: bool = False,
               labels: bool = False, ome: bool = False) -> Path:
    """Write a volume to a zarr store, atomically: one array, or an OME-Zarr image.

    The store is written to a hidden sibling folder and renamed into place at the end, so a
    reader never sees a half-written store.  Every chunk is stored (zeros too) and the array
    keeps the CRC-32 of each chunk (:mod:`geoshade.io.stores.chunks`): reading verifies them.

    Parameters
    ----------
    volume : VoxelVolume
        The volume (numpy, memmap, dask or zarr data; copied in z-slabs of ~64 MiB).
    path : str or Path
        Folder to create (conventionally ``*.zarr``).
    chunks : sequence of 3 int
        Chunk shape ``(cz, cy, cx)`` in array order; clipped to the volume.
    overwrite : bool
        Replace an existing ``path`` (a store geoshade wrote, or a file:
        :func:`geoshade.io.output.check_replace` refuses anything else); otherwise an existing
        path is an error.
    labels : bool
        The values are labels (a segmentation, a selection): the store says so
        (``labels: true``, read back as ``meta["labels"]``; napari opens it as a labels layer).
    ome : bool
        Write an OME-Zarr (NGFF 0.5) image of one level, a zarr v3 group holding the array
        ``0`` (what ``core ingest`` writes, without a pyramid), so that OME-Zarr tools (napari,
        neuroglancer) open it too; default: the array at the root of the store.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.models import VoxelVolume
    >>> vol = VoxelVolume(np.arange(24, dtype=np.uint16).reshape(2, 3, 4), unit="um")
    >>> out = write_zarr(vol, os.path.join(tempfile.mkdtemp(), "v.zarr"))
    >>> int(read_zarr(out).data[1, 2, 3])
    23
    """
    import zarr

    p = Path(path)
    check_replace(p, flag="path")   # a store geoshade wrote or a file, nothing else
    if p.exists() and not overwrite:
        raise InputError(f"{path}: already exists; pass overwrite=True to replace it")
    data = volume.data
    shape = tuple(int(n) for n in data.shape)
    ch = _chunks(chunks, shape)
    dtype = np.dtype(volume.dtype).newbyteorder("=")
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.parent / f".{p.name}.tmp-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    try:
        group = None
        if ome:
            group = zarr.open_group(str(tmp), mode="w", zarr_format=3)
            arr = group.create_array("0", shape=shape, chunks=ch, dtype=dtype, fill_value=0,
                                     dimension_names=("z", "y", "x"),
                                     config={"write_empty_chunks": True})
        else:
            arr = zarr.open_array(store=str(tmp), mode="w", shape=shape, chunks=ch,
                                  dtype=dtype, fill_value=0).with_config(
                {"write_empty_chunks": True})
        plane = max(1, shape[1] * shape[2] * dtype.itemsize)
        step = max(1, SLAB_BYTES // plane // ch[0]) * ch[0]
        crcs: list[int] = []
        for z0 in range(0, shape[0], step):
            slab = data[z0 : z0 + step]
            if hasattr(slab, "compute"):
                slab = slab.compute()
            slab = np.ascontiguousarray(slab, dtype=dtype)
            arr[z0 : z0 + step] = slab
            for r in range(0, slab.shape[0], ch[0]):
                crcs += chunk_crcs(slab[r : r + ch[0]], ch[1:])
        arr.attrs.update(
            {
                "spacing": list(volume.spacing),
                "origin": list(volume.origin),
                "unit": volume.unit,
                "axes": ["z", "y", "x"],
                "checksums": checksum_record(shape, dtype, ch, crcs),
                **({"labels": True} if labels else {}),
            }
        )
        if group is not None:  # the group's record (read_zarr checks it), set last
            group.attrs.update({
                "spacing": list(volume.spacing), "origin": list(volume.origin),
                "unit": volume.unit, "axes": ["z", "y", "x"],
                **multiscales_attrs(volume.name or p.name, [shape], volume.spacing,
                                    volume.origin, volume.unit),
                "ingest": {"complete": True, "source": str(volume.name or ""), "levels": 1,
                           "chunks": list(ch), "dtype": dtype.name, "checksums": ALGORITHM,
                           "writer": "write_zarr"},
                **({"labels": True} if labels else {}),
            })
        publish(tmp, p)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return p


# --------------------------------------------------------------------------------------------
# pyramids (geoshade.io.stores.ingest writes them) and verifying whole stores
# --------------------------------------------------------------------------------------------
def _multiscale(node, path) -> Multiscale | None:
    """A group's checked ``multiscales`` (None: a plain store or group)."""
    if not hasattr(node, "array_keys"):
        return None
    return parse_multiscales(_zarr_step(path, "zarr.json", lambda: dict(node.attrs)), path)


def _datasets(node, path) -> list[str]:
    """The array paths of a group's ``multiscales`` (level 0 first), checked."""
    ms = _multiscale(node, path)
    return [] if ms is None else list(ms.paths)


def store_levels(path) -> int:
    """Number of pyramid levels of a multiscale store (written by
    :func:`geoshade.io.stores.ingest.ingest`, or any OME-Zarr image); 1 for a plain store.

    Examples
    --------
    >>> store_levels("no/such.zarr")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: no/such.zarr: no such file
    """
    node = _open(path)
    if not hasattr(node, "array_keys"):
        return 1
    return len(_datasets(node, path)) or 1


def _level_array(node, path, level: int) -> tuple[Any, str]:
    sub = _datasets(node, path)[level]
    return _zarr_step(path, f"array {sub}", lambda: node[sub]), sub


def read_level(path, level: int = 0) -> VoxelVolume:
    """Level ``level`` of a multiscale store as a lazy :class:`VoxelVolume`.

    Level k has level 0's spacing times the ratio of the levels' ``scale`` in the
    ``multiscales`` metadata (``2**k`` for geoshade's pyramids, and wherever no scale is given)
    and level 0's origin (voxel corners), so all levels occupy the same world box.  Reads are
    checked like :func:`read_zarr`'s.

    Raises
    ------
    InputError
        Missing store or level, an unfinished ingest, damaged metadata, a level of another
        OME-Zarr writer that is not a smaller copy of level 0 (does not fit as an overview).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from geoshade.io.stores.ingest import ingest
    >>> d = tempfile.mkdtemp()
    >>> np.arange(64, dtype=np.uint8).reshape(4, 4, 4).tofile(os.path.join(d, "c.raw"))
    >>> rep = ingest(os.path.join(d, "c.raw"), os.path.join(d, "c.zarr"), chunks=(2, 2, 2),
    ...              levels=2, shape=(4, 4, 4), dtype="uint8")
    >>> v1 = read_level(rep.path, 1)
    >>> v1.shape_xyz, v1.spacing, int(v1.data[1, 1, 1])
    ((2, 2, 2), (2.0, 2.0, 2.0), 42)
    """
    n = store_levels(path)
    try:
        level = int(level)
    except (TypeError, ValueError):
        raise InputError(f"{path}: level: expected an integer, got {level!r}") from None
    if not 0 <= level < n:
        raise InputError(f"{path}: level: expected 0..{n - 1} (the store has {n} levels), got "
                         f"{level}")
    base = read_zarr(path)  # checks completeness, gives level 0
    if level == 0:
        return base
    node = _open(path)
    ms = _multiscale(node, path)
    arr, sub = _level_array(node, path, level)
    crcs = check_record(arr, path, sub)
    ing = _check_complete(_zarr_step(path, "zarr.json", lambda: dict(node.attrs)), path)
    _check_group_record(ing, crcs, path, sub)
    index = _space_index(ms, arr, path, level)
    shape = tuple(int(n) for i, n in zip(index, arr.shape, strict=False) if not isinstance(i, int))
    if len(shape) != 3:
        raise DamagedStoreError(f"{path}: array {sub}: expected a 3D array, got shape "
                                f"{tuple(arr.shape)}")
    shape0 = base.data.shape
    if any(a > b for a, b in zip(shape, shape0, strict=True)) or arr.dtype != base.dtype:
        raise InputError(f"{path}: level {level} (array {sub}, {arr.dtype} {shape}) does not fit "
                         f"as an overview of level 0 ({base.dtype} {tuple(shape0)}): expected "
                         "a smaller array of the same type")
    view = _store_array(arr, path, sub, crcs)
    sk, s0 = (ms.spacing(level), ms.spacing(0)) if ms is not None else (None, None)
    factor = ([a / b for a, b in zip(sk, s0, strict=True)] if sk is not None and s0 is not None
              else [2.0**level] * 3)
    chunks = tuple(int(c) for i, c in zip(index, arr.chunks, strict=False)
                   if not isinstance(i, int))
    meta = {**base.meta, "level": level, "chunks": chunks}
    data = view.as_dask()
    if any(isinstance(i, int) for i in index):
        data = data[index]
    sx, sy, sz = base.spacing
    return VoxelVolume(data=data, spacing=(sx * factor[0], sy * factor[1], sz * factor[2]),
                       origin=base.origin, unit=base.unit, name=f"{base.name}[{level}]",
                       meta=meta)


def verify_store(path, progress: Progress | None = None) -> dict:
    """Read every chunk of every level of a store and check it (``geoshade core verify``).

    Returns
    -------
    dict
        ``store``, ``levels`` (array paths), ``chunks`` (checked), ``checksums`` (True when every
        level carries geoshade's CRC-32s; else chunks were only decoded), ``not_stored`` (chunks
        absent from a store without checksums, read as the fill value).

    Raises
    ------
    DamagedStoreError
        One line: how many chunks are damaged, the first few named.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = write_zarr(VoxelVolume(np.ones((4, 4, 4), np.uint8)), os.path.join(
    ...     tempfile.mkdtemp(), "v.zarr"), chunks=(2, 4, 4))
    >>> r = verify_store(f)
    >>> r["chunks"], r["checksums"]
    (2, True)
    >>> os.remove(os.path.join(f, "c", "1", "0", "0"))
    >>> verify_store(f)
    Traceback (most recent call last):
    ...
    geoshade.io.stores.chunks.DamagedStoreError: ...v.zarr: 1 of 2 chunks damaged: ...
    """
    read_zarr(path)  # the checks at open
    node = _open(path)
    if hasattr(node, "array_keys"):
        ing = _check_complete(_zarr_step(path, "zarr.json", lambda: dict(node.attrs)), path)
        subs = _datasets(node, path)
        arrays = [_level_array(node, path, k) for k in range(len(subs))] if subs else \
            [_pick_array(node, path)[:2]]
    else:
        ing, arrays = None, [(node, "")]
    views = []
    for arr, sub in arrays:
        crcs = check_record(arr, path, sub)
        if hasattr(node, "array_keys"):
            _check_group_record(ing, crcs, path, sub)
        views.append(_store_array(arr, path, sub, crcs))
    total = sum(int(np.prod(v.grid)) for v in views)
    bad: list[str] = []
    done = not_stored = 0
    for view in views:
        for coords in view.chunk_coords():
            done += 1
            if view.crcs is None and not view.chunk_file(coords).exists():
                not_stored += 1
            else:
                try:
                    view.chunk(coords)
                except DamagedStoreError as err:
                    bad.append(str(err).removeprefix(f"{path}: ").split("; ")[0])
            if progress is not None:
                progress(done, total)
    if bad:
        more = f"; and {len(bad) - 3} more" if len(bad) > 3 else ""
        raise DamagedStoreError(f"{path}: {len(bad)} of {total} chunks damaged: "
                                f"{'; '.join(bad[:3])}{more}")
    return {"store": str(path), "levels": [v.path for v in views], "chunks": total,
            "checksums": all(v.crcs is not None for v in views), "not_stored": not_stored}
