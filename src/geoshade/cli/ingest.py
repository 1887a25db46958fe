"""``geoshade core ingest`` and the big-data options of ``core render|porosity``.

- ``geoshade core ingest INPUT -o CORE.zarr`` writes a chunked multiscale zarr store
  (:func:`geoshade.io.stores.ingest.ingest`), with a progress bar, resumable.
- ``geoshade core verify CORE.zarr`` reads every chunk of every level and checks it against the
  CRC-32 recorded when it was written (:func:`geoshade.io.stores.zarr_io.verify_store`).
- ``--scheduler ADDRESS`` (render, porosity): run the dask graphs on that cluster
  (:mod:`geoshade.scheduler`; ``local:N`` starts N local workers).
- ``--dataset PATH`` (render, porosity): the HDF5 dataset to read.
- ``--bricks N`` (render): render in bricks of at most N voxels per side (``0``: never brick;
  default: only when the box exceeds the GPU's limits).
- ``--level K|auto`` (render): a pyramid level of an ingested store (``auto``: the finest level
  whose whole volume fits, for an overview); ``--box`` is then in that level's voxels.

``cli/core.py`` calls :func:`register` and :func:`add_scale_args`, loads volumes with
:func:`load_volume` and passes :func:`scale_kwargs` to the core API.
"""

from __future__ import annotations

import warnings

from geoshade.cli.main import finite_float, volume_hints
from geoshade.cli.progress import progress_bar
from geoshade.core.overview import overview_level
from geoshade.errors import InputError
from geoshade.io import load
from geoshade.io.formats import case_files
from geoshade.io.output import check_replace
from geoshade.io.stores.ingest import PARTIAL_SUFFIX, ingest
from geoshade.io.stores.zarr_io import read_level, verify_store


def add_scale_args(p, render: bool) -> None:
    """The options for volumes beyond one machine's memory."""
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask.distributed scheduler to compute on (tcp://HOST:8786, or local:N "
                        "to start N local worker processes); default: local threads. "
                        "Trust: local:N uses TLS with throw-away certificates, no dashboard; a "
                        "scheduler at an address can run code here: prefer tls:// (certificates "
                        "from dask's config distributed.comm.tls.*)")
    p.add_argument("--dataset", metavar="PATH", help="HDF5 files: the dataset to read")
    if render:
        p.add_argument("--bricks", type=int, metavar="N", default=None,
                       help="render in bricks of at most N voxels per side (0: never; default: "
                            "only when the box exceeds the GPU's texture limit or memory)")
        p.add_argument("--level", default=None, metavar="K|auto",
                       help="pyramid level of an ingested store (auto: the finest that fits, "
                            "an overview of the whole core); --box is in that level's voxels")


def scale_kwargs(args) -> dict:
    """Keyword arguments of ``core.render``/``core.porosity`` from the options."""
    kw = {"scheduler": getattr(args, "scheduler", None)}
    if hasattr(args, "bricks"):
        kw["bricks"] = None if args.bricks is None else (False if args.bricks == 0
                                                         else int(args.bricks))
    return kw


def load_volume(args):
    """Load ``args.volume`` with the volume hints, the HDF5 dataset and the pyramid level; warn
    about what a zarr store's attributes do not say."""
    hints = volume_hints(args)
    if getattr(args, "dataset", None):
        hints["dataset"] = args.dataset
    level = getattr(args, "level", None)
    if level is not None:
        if level == "auto":
            level = overview_level(args.volume)
        else:
            try:
                level = int(level)
            except ValueError:
                raise InputError(f"--level: expected an integer or 'auto', got {level!r}") from None
        vol = read_level(args.volume, level)
        print(f"{args.volume}: pyramid level {level}, {'×'.join(map(str, vol.shape_xyz))} voxels")
    else:
        vol = load(args.volume, **hints)
    if vol.meta.get("format") == "zarr" and vol.meta.get("assumed"):
        warnings.warn(f"{args.volume}: zarr store without geoshade attributes; assumed "
                      f"{'; '.join(vol.meta['assumed'])}", UserWarning, stacklevel=2)
    return vol


def register(csub) -> None:
    """Add ``ingest`` to the ``core`` actions."""
    g = csub.add_parser("ingest", help="write a volume into a chunked multiscale zarr store "
                                       "(resumable, bounded memory)")
    g.add_argument("input", metavar="INPUT",
                   help="folder of TIFF slices, multi-page TIFF, raw file or HDF5")
    g.add_argument("-o", "--output", required=True, metavar="CORE.zarr")
    g.add_argument("--chunks", type=int, nargs=3, metavar=("CZ", "CY", "CX"),
                   default=(128, 128, 128), help="chunk shape (128 128 128)")
    g.add_argument("--levels", type=int, default=None,
                   help="pyramid levels incl. full resolution (default: halve to <= 256)")
    g.add_argument("--downsample", choices=("nearest", "mean"), default="nearest",
                   help="how each level halves the previous (nearest keeps scan values)")
    g.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="raw files: voxels along x, y, z (x varies fastest)")
    g.add_argument("--dtype", help="raw files: uint8, uint16, int16, float32, ...")
    g.add_argument("--endian", choices=("little", "big"), default=None)
    g.add_argument("--offset", type=int, default=None, help="raw files: header bytes to skip")
    g.add_argument("--dataset", metavar="PATH", help="HDF5 files: the dataset to read")
    g.add_argument("--spacing", type=finite_float, nargs=3, metavar=("DX", "DY", "DZ"))
    g.add_argument("--unit", default=None, help="length unit of the spacing (um, mm, ...)")
    g.add_argument("--workers", type=int, default=1,
                   help="slabs written at once by threads (memory: one slab each)")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="write the slabs on a dask.distributed cluster sharing this disk "
                        "(tcp://HOST:8786, or local:N for N local worker processes; a scheduler "
                        "at an address can run code here: prefer tls://)")
    g.add_argument("--overwrite", action="store_true", help="replace an existing store")
    g.add_argument("--verify", action="store_true",
                   help="on resume, re-read every finished slab and check its CRC-32")
    g.set_defaults(func=run_ingest)

    v = csub.add_parser("verify", help="read every chunk of a zarr store and check it against "
                                       "the CRC-32 recorded when it was written")
    v.add_argument("store", metavar="STORE", help="a zarr store (written by core ingest)")
    v.set_defaults(func=run_verify)


def run_verify(args) -> int:
    with progress_bar("verifying chunks", unit="steps") as cb:
        r = verify_store(args.store, progress=cb)
    levels = ", ".join(r["levels"]) or "/"
    if r["checksums"]:
        print(f"{args.store}: {r['chunks']} chunks of {len(r['levels'])} level(s) ({levels}) "
              "match their CRC-32: no damage found")
    else:
        absent = (f"; {r['not_stored']} not stored (read as the fill value)"
                  if r["not_stored"] else "")
        print(f"{args.store}: {r['chunks']} chunks of {len(r['levels'])} level(s) ({levels}) "
              f"decode; the store carries no geoshade checksums, so their values could not be "
              f"verified{absent}")
    return 0


def run_ingest(args) -> int:
    check_replace(args.output, case_files(args.input))   # before any work: one line
    try:
        with progress_bar("ingest", unit="slabs") as cb:
            rep = ingest(
                args.input, args.output, chunks=tuple(args.chunks), levels=args.levels,
                progress=cb, shape=args.shape, dtype=args.dtype, endian=args.endian,
                offset=args.offset, dataset=args.dataset, spacing=args.spacing, unit=args.unit,
                downsample=args.downsample, overwrite=args.overwrite, workers=args.workers,
                scheduler=args.scheduler, verify=args.verify)
    except KeyboardInterrupt:  # one line, said by cli.main
        raise KeyboardInterrupt(f"{args.output}{PARTIAL_SUFFIX} keeps the finished slabs: run "
                                "the same command again to resume") from None
    nx, ny, nz = rep.shape_xyz
    vr = "?" if rep.value_range is None else f"[{rep.value_range[0]}, {rep.value_range[1]}]"
    rate = rep.bytes_read / max(rep.seconds, 1e-9) / 2**20
    resumed = f" ({rep.slabs_skipped} found done)" if rep.slabs_skipped else ""
    print(f"{rep.path}: {nx}×{ny}×{nz} {rep.dtype}, {len(rep.levels)} levels, chunks "
          f"{'×'.join(map(str, rep.chunks))}, values {vr}; {rep.slabs_written} slabs written"
          f"{resumed} in {rep.seconds:.1f} s ({rate:.0f} MiB/s read)")
    for note in rep.notes:
        print(f"  {note}")
    return 0
