"""The saved stack model: ``MODEL.stacks.npz`` (format ``geoshade-stacks``, version 1).

A NumPy ``.npz`` archive (zip of ``.npy`` members, compressed), readable with plain
``numpy.load(path)``; written atomically (temporary file + rename). Members:

=================  ======================  ===============================================
member             shape, dtype            meaning
=================  ======================  ===============================================
``header``         (k,) uint8              UTF-8 JSON, see below
``offsets``        (ncols + 1,) int64      CSR offsets of the columns' intervals
``starts``         (n,) float32            interval start heights, levels above the bottom
``codes``          (n,) int32              material codes, -1 = empty
``borehole``       (ncols,) uint8          1 = borehole column
``log_base``       (ncols,) float32        level where a borehole column's log starts
``legend_codes``   (m,) int32              legend codes (sorted)
``legend_rgba``    (m, 4) uint8            legend colours
=================  ======================  ===============================================

Header JSON: ``{"format": "geoshade-stacks", "version": 1, "shape": [nx, ny], "nlevels": int,
"origin": [x0, y0, z0], "spacing": [dx, dy, dz], "crs": str, "unit": str, "name": str,
"legend_names": [str, ...], "meta": {...}}`` (``meta`` keeps only JSON values). The arrays
follow the contracts of :class:`geoshade.models.stacks.StackModel`, which checks them again on
reading. A reader refuses a file whose version is newer than it knows.
"""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.output import atomic_write_bytes
from geoshade.io.paths import check_file, one_line
from geoshade.io.volumes.npy import NPZ_ERRORS, read_member
from geoshade.models.stacks import Legend, StackModel

FORMAT = "geoshade-stacks"
VERSION = 1
SUFFIX = ".stacks.npz"
MEMBERS = ("header", "offsets", "starts", "codes", "borehole", "log_base", "legend_codes",
           "legend_rgba")


def _json_safe(meta: dict) -> dict:
    out = {}
    for k, v in (meta or {}).items():
        try:
            json.dumps(v)
        except (TypeError, ValueError):
            continue
        out[str(k)] = v
    return out


def write_stacks(path, model: StackModel) -> Path:
    """Save ``model`` as a versioned ``.stacks.npz`` archive, atomically.

    Examples
    --------
    >>> import tempfile, os
    >>> m = StackModel([0, 2], [0, 4], [3, -1], (1, 1), 6, name="demo")
    >>> p = write_stacks(os.path.join(tempfile.mkdtemp(), "m.stacks.npz"), m)
    >>> r = read_stacks(p)
    >>> r.codes.tolist(), r.nlevels, r.name
    ([3, -1], 6, 'demo')
    """
    header = {"format": FORMAT, "version": VERSION, "shape": list(model.shape),
              "nlevels": model.nlevels, "origin": list(model.origin),
              "spacing": list(model.spacing), "crs": model.crs, "unit": model.unit,
              "name": model.name, "legend_names": list(model.legend.names),
              "meta": _json_safe(model.meta)}
    buf = io.BytesIO()
    np.savez_compressed(
        buf, header=np.frombuffer(json.dumps(header).encode(), np.uint8),
        offsets=model.offsets.astype(np.int64), starts=model.starts.astype(np.float32),
        codes=model.codes.astype(np.int32), borehole=model.borehole.astype(np.uint8),
        log_base=model.log_base.astype(np.float32),
        legend_codes=model.legend.codes.astype(np.int32),
        legend_rgba=model.legend.rgba.astype(np.uint8))
    return atomic_write_bytes(path, buf.getvalue())


def is_stackfile(path) -> bool:
    """True for a zip archive with a ``header`` member saying ``geoshade-stacks``."""
    if not Path(path).is_file():
        return False
    try:
        with zipfile.ZipFile(path) as z:
            if "header.npy" not in z.namelist():
                return False
        with np.load(path, allow_pickle=False) as f:
            return json.loads(bytes(f["header"]).decode()).get("format") == FORMAT
    except (*NPZ_ERRORS, AttributeError, TypeError, RecursionError):
        return False


def read_stacks(path) -> StackModel:
    """Read a ``.stacks.npz`` archive written by :func:`write_stacks`.

    Raises
    ------
    InputError
        Missing or unreadable file, a member missing, another format, a newer version, or
        arrays that break the model's contracts.
    """
    p = check_file(path, "a .stacks.npz file")
    if not zipfile.is_zipfile(p):
        raise InputError(f"{path}: not a .npz archive (a zip file); expected a geoshade stack "
                         "model")
    try:
        with np.load(p, allow_pickle=False) as f:
            missing = [m for m in MEMBERS if m not in f.files]
            if missing:
                raise InputError(f"{path}: not a geoshade stack model (members {missing} "
                                 "missing)")
            arrays = {m: read_member(f, m, path) for m in MEMBERS}
    except InputError:
        raise
    except NPZ_ERRORS as exc:
        raise InputError(f"{path}: not a readable .npz archive ({one_line(exc)})") from None
    try:
        header = json.loads(bytes(arrays["header"]).decode())
    except (ValueError, UnicodeDecodeError, TypeError):
        raise InputError(f"{path}: header: not valid UTF-8 JSON") from None
    except RecursionError:  # 100,000 nested [ (a header nests 2 deep)
        raise InputError(f"{path}: header: JSON nested too deeply") from None
    if not isinstance(header, dict):
        raise InputError(f"{path}: header: expected a JSON object, got {type(header).__name__}")
    if header.get("format") != FORMAT:
        raise InputError(f"{path}: header format {header.get('format')!r}; expected {FORMAT!r}")
    version = header.get("version")
    if not isinstance(version, int) or version > VERSION or version < 1:
        raise InputError(f"{path}: format version {version!r}; this geoshade reads versions "
                         f"1..{VERSION}")
    try:
        legend = Legend(arrays["legend_codes"], tuple(header["legend_names"]),
                        arrays["legend_rgba"])
        return StackModel(
            offsets=arrays["offsets"], starts=arrays["starts"], codes=arrays["codes"],
            shape=tuple(header["shape"]), nlevels=int(header["nlevels"]), legend=legend,
            origin=tuple(header["origin"]), spacing=tuple(header["spacing"]),
            borehole=arrays["borehole"].astype(bool), log_base=arrays["log_base"],
            crs=header.get("crs", ""),
            unit=header.get("unit", ""), name=header.get("name", "") or p.name,
            meta={**header.get("meta", {}), "format": FORMAT, "source": str(path)})
    except KeyError as exc:
        raise InputError(f"{path}: header: field {exc} missing") from None
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    except (TypeError, ValueError, AttributeError) as exc:  # fields of the wrong type
        raise InputError(f"{path}: header: damaged ({one_line(exc)})") from None


def describe_stacks(model: StackModel, stats: bool = True) -> dict:
    """Summary of a :class:`StackModel` for ``geoshade info`` (``DESCRIBERS`` entry).

    >>> d = describe_stacks(StackModel([0, 2], [0, 4], [3, -1], (1, 1), 6))
    >>> d["kind"], d["columns"], d["intervals"], d["max_intervals"]
    ('stacks', 1, 2, 2)
    """
    nx, ny = model.shape
    d = {"kind": "stacks", "name": model.name, "format": model.meta.get("format", ""),
         "source": model.meta.get("source", ""), "columns_xy": [nx, ny],
         "columns": model.ncols, "nlevels": model.nlevels, "intervals": model.nintervals,
         "max_intervals": model.max_intervals, "boreholes": int(model.borehole.sum()),
         "materials": len(model.legend), "spacing": list(model.spacing),
         "origin": list(model.origin), "unit": model.unit, "crs": model.crs,
         "bytes": model.nbytes}
    if stats:
        lo, hi = model.occupied_levels()
        d["occupied_levels"] = [lo, hi]
    return d
