"""Corner-point grids out of core: a case streamed into a chunked zarr store, and opened lazily.

:func:`ingest_grid` writes an ECLIPSE/OPM case (EGRID + INIT + UNRST), a GRDECL file or deck
(streamed by :mod:`geoshade.io.grids.grdecl_stream`) — or any
:class:`~geoshade.models.CornerPointGrid`, e.g. a ROFF file read in memory — into::

    CASE.zarr/                     zarr v3 group; attribute ``grid_store`` {complete, version,
                                   dims, chunks, ...} plus units, mapaxes, step dates, faults,
                                   ``summaries`` (each cell array's colour-scale summary over
                                   the active cells, combined from the slabs' at ingest),
                                   ``distinct_codes`` (an integer array's distinct active
                                   values, null beyond 4096: what draws it as categories)
      coord     (nx+1, ny+1, 6)    float64  pillars
      zcorn     (2nx, 2ny, 2nz)    float32  chunks (2ci, 2cj, 2ck)
      actnum    (nx, ny, nz)       uint8    chunks (ci, cj, ck)
      props/<NAME> (nx, ny, nz)    INIT properties (NaN / 0 in inactive cells)
      steps/<KW> (nsteps, nx, ny, nz)  report-step keywords, chunks (1, ci, cj, ck)

Arrays are indexed ``[i, j, k]`` as in the in-memory grid.  The case is streamed in *k-slabs*
of ``ck`` layers (the files' order): a slab spans the whole ``i, j`` extent and one chunk in
``k``, so every write fills whole chunks, and at most one slab (plus its compressed copy) is in
memory.  Big records are read in pieces: an unformatted record's data are blocks of 1000
values between 4-byte markers, so the values ``[q0, q1)`` are one plain file read of the blocks
that hold them (:func:`geoshade.io.stores.ecl_source.read_values`); formatted files are read
whole per record.

Resumable and never half-presented, as :mod:`geoshade.io.stores.ingest` (whose helpers it uses): the
store is written as ``CASE.zarr.partial`` under ``CASE.zarr.lock``; after each slab the CRC-32s
of its chunks go to ``CASE.zarr.partial.progress.json``; a rerun skips the recorded slabs
(re-checking the last one); the checksum records and ``grid_store.complete`` are written last
and the folder renamed.  :func:`open_grid_store` refuses an incomplete store and reads every
chunk through :class:`~geoshade.io.stores.chunks.StoreArray` (CRC-checked, dask).
"""

from __future__ import annotations

import contextlib
import inspect
import json
import shutil
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geoshade.errors import GeoshadeError, InputError
from geoshade.io import formats
from geoshade.io.grids.grdecl_stream import NeedsMemory
from geoshade.io.output import check_replace, read_store_meta
from geoshade.io.paths import check_memory, one_line
from geoshade.io.stores import grid_index
from geoshade.io.stores.binding import SampledRecords, UnboundRecordWarning, arrays_digest
from geoshade.io.stores.chunks import (
    PENDING,
    DamagedStoreError,
    StoreArray,
    check_record,
    checksum_record,
    grid_shape,
    value_crc,
)
from geoshade.io.stores.grid_attrs import (
    binding,
    read_faults,
    read_mapaxes,
    read_meta,
    read_nactive,
    read_steps,
    read_text,
    sealed,
)
from geoshade.io.stores.grid_sources import GridSource, ModelSource
from geoshade.io.stores.ingest_lock import IngestLock
from geoshade.io.stores.partial_store import (
    _disk_error,
    _load_progress,
    _progress_path,
    _save_progress,
    publish,
    refuse_planted,
)
from geoshade.io.stores.zarr_io import read_zarr
from geoshade.models import CornerPointGrid
from geoshade.models.summary import (
    SummaryCheck,
    codes_agree,
    codes_part,
    merge_codes,
    part_to_json,
    read_codes,
    read_summaries,
    slab_summaries,
    summary_part,
)
from geoshade.progress import Progress, scaled
from geoshade.scheduler import dask_get

__all__ = ["DEFAULT_CHUNKS", "GridIngestReport", "ingest_grid", "is_grid_store",
           "open_grid_store", "read_store", "write_grid_store"]

#: format version of the ``grid_store`` attribute
STORE_VERSION = 1
#: cells per chunk along i, j, k
DEFAULT_CHUNKS = (128, 128, 16)
PARTIAL_SUFFIX = ".partial"
#: test hook: called with the number of slabs done after each slab is recorded
_after_slab = None


# --------------------------------------------------------------------------------------------
# the writer
# --------------------------------------------------------------------------------------------
@dataclass
class GridIngestReport:
    """What :func:`ingest_grid` did."""

    path: Path
    dims: tuple[int, int, int]
    chunks: tuple[int, int, int]
    slabs: int = 0
    slabs_written: int = 0
    slabs_skipped: int = 0
    resumed: bool = False
    seconds: float = 0.0
    memory_bytes: int = 0
    arrays: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    index: grid_index.IndexBuild | None = None  # the index built before the store was presented


def _check_chunks(chunks, dims) -> tuple[int, int, int]:
    try:
        ch = tuple(int(c) for c in chunks)
    except (TypeError, ValueError):
        ch = ()
    if len(ch) != 3 or min(ch) < 1:
        raise InputError(f"chunks: expected three positive integers CI CJ CK, got {chunks!r}")
    return tuple(min(c, n) for c, n in zip(ch, dims, strict=True))  # type: ignore[return-value]


def _arrays(src: GridSource, ch) -> dict[str, tuple]:
    """name -> (shape, chunks, dtype) of every array of the store."""
    nx, ny, nz = src.dims
    ci, cj, ck = ch
    nt = len(src.step_dates)
    cells = ((nx, ny, nz), (ci, cj, ck))
    out = {"coord": ((nx + 1, ny + 1, 6), (min(nx + 1, 1024), min(ny + 1, 1024), 6), "float64"),
           "zcorn": ((2 * nx, 2 * ny, 2 * nz), (2 * ci, 2 * cj, 2 * ck), "float32"),
           "actnum": (*cells, "uint8")}
    for name, dt in src.properties.items():
        out[f"props/{name}"] = (*cells, np.dtype(dt).name)
    for kw, dt in src.step_keywords.items():
        out[f"steps/{kw}"] = ((nt, nx, ny, nz), (1, ci, cj, ck), np.dtype(dt).name)
    return out


def slab_bytes(src: GridSource, ck: int) -> int:
    """Bytes in memory while one slab of ``ck`` layers is written (ZCORN read, converted and
    encoded, the largest cell array twice)."""
    nx, ny, _ = src.dims
    per = nx * ny * ck
    return int(3 * 32 * per + 3 * 8 * per + (16 * (nx + 1) * (ny + 1) * 6 if ck else 0))


def _crcs_2d(slab: np.ndarray, ch_ij) -> list[int]:
    """CRC-32 of each chunk of a slab one chunk deep in k: (ic, jc) in C order."""
    ci, cj = ch_ij
    return [value_crc(slab[a:a + ci, b:b + cj]) for a in range(0, slab.shape[0], ci)
            for b in range(0, slab.shape[1], cj)]


def _write_slab(g, src: GridSource, arrays: dict, s: int, ck: int, a0: int) -> dict:
    """Write slab ``s`` of every array; its active count and chunk CRCs."""
    nz = src.dims[2]
    k0, k1 = s * ck, min(nz, (s + 1) * ck)
    crc: dict[str, list] = {}
    z = src.zcorn(k0, k1)
    g["zcorn"][:, :, 2 * k0:2 * k1] = z
    crc["zcorn"] = _crcs_2d(z, arrays["zcorn"][1][:2])
    del z
    act = src.actnum(k0, k1)
    g["actnum"][:, :, k0:k1] = act
    crc["actnum"] = _crcs_2d(act, arrays["actnum"][1][:2])
    # the colour-scale summary of each cell array over this slab's active cells (one compiled
    # pass while the slab is in memory; :func:`_finish` combines the slabs')
    summ: dict[str, list] = {}
    codes: dict[str, list | None] = {}   # an integer array's distinct values (categories)
    for name in src.properties:
        v = src.prop(name, k0, k1, act, a0)
        g[f"props/{name}"][:, :, k0:k1] = v
        crc[f"props/{name}"] = _crcs_2d(v, arrays[f"props/{name}"][1][:2])
        summ[f"props/{name}"] = part_to_json(summary_part(v, act))
        if np.issubdtype(v.dtype, np.integer):
            codes[f"props/{name}"] = codes_part(v, act)
    for kw in src.step_keywords:
        crc[f"steps/{kw}"] = []
        summ[f"steps/{kw}"] = []
        for t in range(len(src.step_dates)):
            v = src.step(t, kw, k0, k1, act, a0)
            g[f"steps/{kw}"][t, :, :, k0:k1] = v
            crc[f"steps/{kw}"].append(_crcs_2d(v, arrays[f"steps/{kw}"][1][1:3]))
            summ[f"steps/{kw}"].append(part_to_json(summary_part(v, act)))
    return {"nact": int(np.count_nonzero(act)), "crc": crc, "summary": summ, "codes": codes}


def _record(arr_shape, chunks, dtype, slabs: list[dict], name: str) -> dict:
    """The checksum record of a slab-written array from the slabs' CRCs."""

    gs = grid_shape(arr_shape, chunks)
    if name.startswith("steps/"):
        crcs = np.zeros(gs, np.int64)
        for s, d in enumerate(slabs):
            for t, lst in enumerate(d["crc"][name]):
                crcs[t, :, :, s] = np.asarray(lst).reshape(gs[1], gs[2])
    else:
        crcs = np.zeros(gs, np.int64)
        for s, d in enumerate(slabs):
            crcs[:, :, s] = np.asarray(d["crc"][name]).reshape(gs[0], gs[1])
    return checksum_record(arr_shape, dtype, chunks, crcs.reshape(-1).tolist())


def write_grid_store(src: GridSource, out, chunks=DEFAULT_CHUNKS, progress: Progress | None
                     = None, overwrite: bool = False, compressor: str = "zstd",
                     input_label: str = "", index=None,
                     index_progress: Progress | None = None, inputs=()) -> GridIngestReport:
    """Stream a :class:`GridSource` into a grid store at ``out`` (see :func:`ingest_grid`);
    ``inputs``: the files it is read from (``out`` may not be or hold one:
    :func:`geoshade.io.output.check_replace`)."""
    import zarr
    from zarr.codecs import BloscCodec

    t0 = time.perf_counter()
    out = Path(out)
    check_replace(out, inputs)   # never a folder it did not write, the input, the working one
    ch = _check_chunks(chunks, src.dims)
    if out.exists() and not overwrite:
        raise InputError(f"{out}: already exists; pass --overwrite (overwrite=True) to replace it")
    nx, ny, nz = src.dims
    nslabs = -(-nz // ch[2])
    need = slab_bytes(src, ch[2])
    check_memory(need, input_label or src.name, f"and writing slabs of {ch[2]} layers of "
                 f"{nx}×{ny} cells", "use a smaller --chunks CK")
    arrays = _arrays(src, ch)
    params = {"version": STORE_VERSION, "input": input_label or src.name,
              "fingerprint": src.fingerprint, "dims": list(src.dims), "chunks": list(ch),
              "compressor": compressor,
              "arrays": {k: [list(v[0]), list(v[1]), v[2]] for k, v in arrays.items()}}
    report = GridIngestReport(out, src.dims, ch, nslabs, memory_bytes=need,
                              arrays=list(arrays))
    partial = out.with_name(out.name + PARTIAL_SUFFIX)
    refuse_planted(partial)
    made = [d for d in (out.parent, *out.parent.parents) if not d.exists()]
    out.parent.mkdir(parents=True, exist_ok=True)
    ok = False
    try:
        with IngestLock(out, params["input"], task="grid ingest"):
            fresh = not partial.exists()
            try:
                _write_locked(src, out, partial, params, arrays, ch, nslabs, report, progress,
                              overwrite, BloscCodec(cname=compressor, clevel=3,
                                                    shuffle="shuffle"), zarr,
                              (index, index_progress))
            except GeoshadeError as err:
                if fresh and _disk_error(err) is None:
                    shutil.rmtree(partial, ignore_errors=True)
                    _progress_path(partial).unlink(missing_ok=True)
                raise
            except OSError as err:
                disk = _disk_error(err)
                if disk is None:
                    raise
                raise InputError(f"{out}: disk full while writing the store "
                                 f"({disk.strerror or disk}); the unfinished store "
                                 f"{partial.name} is kept: free space and run the same ingest "
                                 "again to resume") from None
        ok = True
    finally:
        if not ok:
            for d in made:
                with contextlib.suppress(OSError):
                    d.rmdir()
    report.seconds = time.perf_counter() - t0
    return report


def _write_locked(src, out, partial, params, arrays, ch, nslabs, report, progress, overwrite,
                  codec, zarr, index=(None, None)) -> None:
    if out.exists() and not overwrite:
        raise InputError(f"{out}: already exists; pass --overwrite (overwrite=True) to replace it")
    state = _load_progress(partial) if partial.exists() else None
    if state is not None and state.get("params") != params:
        if not overwrite:
            diff = sorted(k for k in params if state.get("params", {}).get(k) != params[k])
            raise InputError(f"{partial}: an unfinished ingest with another input or settings "
                             f"({', '.join(diff)} differ); pass --overwrite (overwrite=True) "
                             "to start again")
        state = None
    if state is None:
        if partial.exists():
            shutil.rmtree(partial)
        g = zarr.open_group(str(partial), mode="w", zarr_format=3)
        g.attrs.update({"grid_store": {"complete": False, "version": STORE_VERSION,
                                       "source": Path(params["input"]).name}})
        for name, (shape, chunks, dt) in arrays.items():
            g.create_array(name, shape=shape, chunks=chunks, dtype=dt, compressors=codec,
                           fill_value=np.nan if np.dtype(dt).kind == "f" else 0,
                           config={"write_empty_chunks": True},
                           attributes={"checksums": PENDING})
        g["coord"][...] = src.coord()
        state = {"params": params, "slabs": []}
        _save_progress(partial, state)
    else:
        report.resumed = True
        g = zarr.open_group(str(partial), mode="r+")
        slabs = state["slabs"]
        if slabs:  # the last recorded slab is checked again (it may have been cut short)
            s = len(slabs) - 1
            k0, k1 = s * ch[2], min(src.dims[2], (s + 1) * ch[2])
            z = np.asarray(g["zcorn"][:, :, 2 * k0:2 * k1])
            if _crcs_2d(z, arrays["zcorn"][1][:2]) != slabs[-1]["crc"]["zcorn"]:
                slabs.pop()
        report.slabs_skipped = len(state["slabs"])
    g = zarr.open_group(str(partial), mode="r+")
    g = _WriteGroup(g)
    slabs = state["slabs"]
    for s in range(len(slabs), nslabs):
        a0 = sum(d["nact"] for d in slabs)
        slabs.append(_write_slab(g, src, arrays, s, ch[2], a0))
        _save_progress(partial, state)
        report.slabs_written += 1
        if progress is not None:
            progress(len(slabs), nslabs)
        if _after_slab is not None:
            _after_slab(len(slabs))
    report.index = _finish(partial, out, src, arrays, state, *index)


class _WriteGroup:
    """A zarr group whose arrays are opened once and store every chunk (zeros too)."""

    def __init__(self, g):
        self.g, self.cache = g, {}

    def __getitem__(self, name):
        if name not in self.cache:
            self.cache[name] = self.g[name].with_config({"write_empty_chunks": True})
        return self.cache[name]


def _finish(partial: Path, out: Path, src: GridSource, arrays: dict, state: dict,
            index=None, index_progress=None) -> grid_index.IndexBuild | None:
    import zarr

    g = zarr.open_group(str(partial), mode="r+")
    coord = np.asarray(g["coord"][...])

    cshape, cch, cdt = arrays["coord"]
    crcs = [value_crc(coord[tuple(slice(i * c, (i + 1) * c) for i, c in zip(idx, cch,
                                                                            strict=True))])
            for idx in np.ndindex(*grid_shape(cshape, cch))]
    records = {"coord": checksum_record(cshape, cdt, cch, crcs)}
    g["coord"].attrs["checksums"] = records["coord"]
    for name, (shape, chunks, dt) in arrays.items():
        if name != "coord":
            records[name] = _record(shape, chunks, dt, state["slabs"], name)
            g[name].attrs["checksums"] = records[name]
    faults = [{"name": f.name, "faces": np.asarray(f.faces).tolist()} for f in src.faults]
    attrs = {
        "units": src.units, "name": Path(src.name).name,
        "mapaxes": None if src.mapaxes is None else [float(v) for v in src.mapaxes],
        "step_dates": list(src.step_dates), "step_seqnum": [int(v) for v in src.step_seqnum],
        "faults": faults, "meta": {k: v for k, v in src.meta.items() if _jsonable(v)},
        "grid_store": {"complete": True, "version": STORE_VERSION,
                       "source": Path(state["params"]["input"]).name, "dims": list(src.dims),
                       "chunks": state["params"]["chunks"],
                       "nactive": int(sum(d["nact"] for d in state["slabs"])),
                       "properties": list(src.properties),
                       "step_keywords": list(src.step_keywords),
                       "checksums": "crc32"}}
    summaries = slab_summaries([d.get("summary") for d in state["slabs"]],
                               {k: v[0][0] for k, v in arrays.items() if k.startswith("steps/")},
                               [k for k in arrays if k.startswith("props/")])
    if summaries is not None:
        attrs["summaries"] = summaries
    slabs = state["slabs"]
    if slabs and all("codes" in d for d in slabs):   # (not a resume of older slabs)
        attrs["distinct_codes"] = {n: merge_codes(d["codes"][n] for d in slabs)
                                   for n in slabs[0]["codes"]}
    # every record bound to the arrays' checksums (binding.py), as JSON will give it back
    attrs = json.loads(json.dumps(attrs))
    digest = arrays_digest((n, r["shape"], r["dtype"], r["chunks"], r["crc32"])
                           for n, r in records.items())
    g.attrs.update(sealed(attrs, digest))
    built = None
    if index is not None:  # the index (grid_index.py), before the store is presented
        built = grid_index.build_index(open_grid_store(partial), partial / grid_index.GROUP,
                                       index, index_progress)
        g.attrs[grid_index.ATTR] = built.attrs
    _progress_path(partial).unlink(missing_ok=True)
    publish(partial, out)
    return built


def _jsonable(v) -> bool:
    try:
        json.dumps(v)
    except (TypeError, ValueError):
        return False
    return True


def ingest_grid(case, out, chunks=DEFAULT_CHUNKS, progress: Progress | None = None,
                overwrite: bool = False, compressor: str = "zstd", index=None,
                index_progress: Progress | None = None) -> GridIngestReport:
    """Stream a corner-point case into a chunked zarr grid store (see the module text).

    Parameters
    ----------
    case : str or Path
        Any file of an ECLIPSE/OPM case (EGRID + INIT beside it, restarts used when present:
        streamed in pieces), or a GRDECL file / ``.DATA`` deck (scanned once, then parsed
        slab by slab: :mod:`geoshade.io.grids.grdecl_stream`, edit keywords and BOXes included;
        block-centred geometry is read in memory, as ``notes`` says).
    out : str or Path
        The store to write (``CASE.zarr``).
    chunks : (ci, cj, ck)
        Cells per chunk; ZCORN chunks are twice as large along each axis.  Memory is about
        ``slab_bytes``: a slab of ``ck`` layers of ``nx × ny`` cells (checked before start).
    progress : callable(done, total), optional
        Called after each slab.
    overwrite : bool
        Replace an existing store (or restart an unfinished ingest with other settings).
    compressor : str
        Blosc compressor name (zstd, lz4, ...).
    index : callable(grid, progress) -> dict, optional
        The index builder (:func:`geoshade.compute.grid.index_faces.store_index`, passed in:
        io cannot import compute): the index is written before the store is presented,
        ``report.index``; ``index_progress`` is called while it is built.

    Returns
    -------
    GridIngestReport

    Examples
    --------
    >>> import tempfile, os
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> from geoshade.io.grids.grdecl_writer import write_grdecl
    >>> d = tempfile.mkdtemp()
    >>> _ = write_grdecl(synthetic_grid(6, 5, 4), os.path.join(d, "g.grdecl"))
    >>> rep = ingest_grid(os.path.join(d, "g.grdecl"), os.path.join(d, "g.zarr"), chunks=(4, 4, 2))
    >>> rep.slabs, open_grid_store(rep.path).dims
    (2, (6, 5, 4))
    """

    p = Path(case)
    if not p.exists():
        raise InputError(f"{case}: no such file")
    if Path(out).resolve() == p.resolve():
        raise InputError(f"{out}: the output would replace the input")
    inputs = formats.case_files(p)
    check_replace(out, inputs)   # before anything is read: one line
    fmt = formats.ingested_by(p, "grid")   # the format table's rows that grid ingest takes
    src: GridSource | None = None
    note = ""
    if fmt.source is not None:   # streamed: an ECLIPSE case by records, GRDECL/decks by slabs
        if Path(out).exists() and not overwrite:  # before a scan of the whole text
            raise InputError(f"{out}: already exists; pass --overwrite (overwrite=True) to "
                             "replace it")
        stream = formats.resolve(fmt.source)
        takes = "progress" in inspect.signature(stream).parameters
        try:
            src = stream(p, **({"progress": scaled(progress, 0, 1000, 1000)} if takes else {}))
        except NeedsMemory as why:
            note = f"read in memory, not streamed: {why}"
    if src is None:  # ROFF, or what a stream cannot represent: read into memory by the
        # row's reader, then written
        grid = fmt.function()(p)
        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"{case}: not a corner-point grid (got {type(grid).__name__})")
        src = ModelSource(grid, str(p))
    rep = write_grid_store(src, out, chunks, progress, overwrite, compressor,
                           str(p.resolve()), index, index_progress, inputs)
    if note:
        rep.notes.append(note)
    return rep


# --------------------------------------------------------------------------------------------
# reading
# --------------------------------------------------------------------------------------------
def _group_attrs(path: Path) -> dict | None:
    meta = read_store_meta(path)   # a regular file only (a FIFO would block), JSON, not deep
    attrs = meta.get("attributes") if isinstance(meta, dict) else None
    return attrs if isinstance(attrs, dict) else None


def read_store(path):
    """A zarr store: a grid store (``grid_store`` attribute) as a lazy corner-point grid, any
    other store as a volume (:func:`geoshade.io.stores.zarr_io.read_zarr`); the reader of the
    ``zarr`` row of :mod:`geoshade.io.formats`."""
    return open_grid_store(path) if is_grid_store(path) else read_zarr(path)


def is_grid_store(path) -> bool:
    """Whether ``path`` is a geoshade grid store (complete or not): its group has a
    ``grid_store`` attribute (a core store has ``ingest`` instead)."""
    attrs = _group_attrs(Path(path))
    return attrs is not None and "grid_store" in attrs


def open_grid_store(path) -> CornerPointGrid:
    """A grid store as a :class:`CornerPointGrid` whose ZCORN, ACTNUM, properties and report
    steps are dask arrays over the store (every chunk CRC-checked when read); COORD is read.

    ``meta["store"]`` is the path, ``meta["chunks"]`` the cell chunks (ci, cj, ck),
    ``meta["step_keywords"]``, ``meta["unrst_seqnum"]``, ``meta["format"]`` "grid-store".

    Raises
    ------
    InputError
        Not a grid store, an incomplete one (an ingest running or interrupted), or damaged
        metadata (one line); a damaged chunk is one line when it is read.
    """
    p = Path(path)
    attrs = _group_attrs(p)
    if attrs is None or "grid_store" not in attrs:
        raise InputError(f"{path}: not a geoshade grid store (no 'grid_store' attribute in "
                         "zarr.json); make one with 'geoshade grid ingest'")
    gs = attrs["grid_store"]
    if not isinstance(gs, dict) or not gs.get("complete"):
        raise InputError(f"{path}: incomplete grid store (an ingest is still writing it, or was "
                         "interrupted); run the same 'geoshade grid ingest' again to finish it")
    try:
        dims = tuple(int(v) for v in gs["dims"])
        chunks = tuple(int(v) for v in gs["chunks"])
        for key in ("properties", "step_keywords"):
            if not isinstance(gs.get(key, []), list):
                raise ValueError(f"{key}: expected a list of names")
        props = [str(v) for v in gs.get("properties", [])]
        kws = [str(v) for v in gs.get("step_keywords", [])]
        if len(dims) != 3 or len(chunks) != 3 or min(dims) < 1 or min(chunks) < 1:
            raise ValueError("dims/chunks: expected three positive integers each")
    except (KeyError, TypeError, ValueError, OverflowError) as err:
        raise DamagedStoreError(f"{path}: damaged 'grid_store' attribute "
                                f"({one_line(err)})") from None
    import zarr

    try:
        root = zarr.open_group(str(p), mode="r")
    except Exception as err:
        raise DamagedStoreError(f"{path}: cannot be opened ({one_line(err)})") from None
    step_dates, seqnum = read_steps(attrs.get("step_dates"), attrs.get("step_seqnum"), path)
    rows: list[tuple] = []   # (name, shape, dtype, chunks, crcs) of every array: the digest
    views: dict[str, StoreArray] = {}

    def array(name: str, shape) -> StoreArray:
        try:
            arr = root[name]
        except Exception as err:
            raise DamagedStoreError(f"{path}: array {name} is missing or damaged "
                                    f"({one_line(err)})") from None
        crcs = check_record(arr, str(path), name)
        if tuple(arr.shape) != tuple(shape):
            raise DamagedStoreError(f"{path}: array {name} has shape {tuple(arr.shape)}, "
                                    f"expected {tuple(shape)}")
        rows.append((name, arr.shape, arr.dtype, arr.chunks, crcs or []))
        views[name] = StoreArray(p, name, str(path), crcs)
        return views[name]

    nx, ny, nz = dims
    nt = len(step_dates)
    coord = array("coord", (nx + 1, ny + 1, 6))[...]
    zcorn = array("zcorn", (2 * nx, 2 * ny, 2 * nz)).as_dask()
    actnum = array("actnum", dims).as_dask()
    if views["actnum"].chunks != chunks:
        raise DamagedStoreError(f"{path}: damaged 'grid_store' attribute (chunks "
                                f"{list(chunks)}, its arrays' are {list(views['actnum'].chunks)})")
    properties = {n: array(f"props/{n}", dims).as_dask() for n in props}
    step_arrays = {kw: array(f"steps/{kw}", (nt, *dims)).as_dask() for kw in kws}
    steps = [{kw: a[t] for kw, a in step_arrays.items()} for t in range(nt)]
    faults = read_faults(attrs.get("faults"), dims, path)
    mapaxes = read_mapaxes(attrs.get("mapaxes"), path)
    units = read_text(attrs.get("units"), "units", path)
    nactive = read_nactive(gs.get("nactive"), nx * ny * nz, path)
    try:  # the colour-scale summaries stored at ingest ({} for an older store)
        summaries = read_summaries(attrs.get("summaries"), props, kws, nt)
    except (TypeError, ValueError) as err:
        raise DamagedStoreError(f"{path}: damaged 'summaries' attribute "
                                f"({one_line(err)})") from None
    try:  # the integer arrays' distinct values stored at ingest ({} for an older store)
        codes = read_codes(attrs.get("distinct_codes"), props)
    except (TypeError, ValueError) as err:
        raise DamagedStoreError(f"{path}: damaged 'distinct_codes' attribute "
                                f"({one_line(err)})") from None
    meta = read_meta(attrs.get("meta"), path)
    # what is derived from the arrays is used only where it is bound to them (binding.py)
    digest = arrays_digest(rows)
    derived_ok, described_ok, why = binding(attrs, digest)
    if not derived_ok:
        summaries, codes, nactive = {}, {}, None
    else:   # each record checked against a chunk of its array where it is first used
        summaries = SampledRecords(summaries, views, views["actnum"],
                                   SummaryCheck(nactive), "summary", str(path), digest)
        codes = SampledRecords(codes, views, views["actnum"], codes_agree, "code table",
                               str(path), digest)
    if why:
        warnings.warn(_unbound_line(path, derived_ok, described_ok, why),
                      UnboundRecordWarning, stacklevel=2)
    # the format the grid was read from (ROFF: -999 codes mean "no value") beside the store's
    meta.setdefault("source_format", meta.get("format", ""))
    meta.update(store=str(p), chunks=chunks, format="grid-store",
                source=str(gs.get("source", "")), step_keywords=kws, unrst_seqnum=seqnum,
                summaries=summaries, distinct_codes=codes, digest=digest,
                bound={"derived": derived_ok, "described": described_ok, "why": why})
    if nactive is None:   # not bound to ACTNUM: counted from it (one pass, chunk by chunk)
        nactive = int((actnum != 0).sum().compute(scheduler=dask_get(None)))
    meta["nactive"] = nactive
    grid = CornerPointGrid(coord=coord, zcorn=zcorn, actnum=actnum, mapaxes=mapaxes,
                           properties=properties, steps=steps, step_dates=step_dates,
                           faults=faults, units=units, name=str(p), meta=meta)
    # the store's own arrays (what its summaries and index describe; a --param may add others)
    grid.__dict__["_store_arrays"] = [*((f"props/{n}", None, a) for n, a in properties.items()),
                                      *((f"steps/{k}", t, s[k]) for t, s in enumerate(steps)
                                        for k in s)]
    return grid


def _unbound_line(path, derived_ok: bool, described_ok: bool, why: str) -> str:
    """The one line that says which of a store's records are not bound to its arrays."""
    parts = []
    if not derived_ok:
        parts.append("its summaries, code tables and active count are not used (computed "
                     "from the data)")
    if not described_ok:
        parts.append("its faults, map axes, units and dates are used as they are")
    again = "; 'geoshade grid ingest' it again to keep them" if "older" in why else ""
    return f"{path}: {why}: {'; '.join(parts)}{again}"
