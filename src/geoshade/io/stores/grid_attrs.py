"""A grid store's root attributes: sealed when written, read back checked.

:mod:`geoshade.io.stores.grid_store` writes the attributes of a finished store through
:func:`sealed` — the arrays' digest and the seals of what is derived from them (summaries,
code tables, the active count) and of what describes them (faults, map axes, units, dates,
names, the layout) (:mod:`geoshade.io.stores.binding`) — and reads them back through the
``read_*`` functions here: an attribute of the wrong type or shape is one line naming the store
and the attribute (:class:`~geoshade.io.stores.chunks.DamagedStoreError`), never an internal
error; :func:`binding` says whether the records still match the arrays opened.
"""

from __future__ import annotations

import numpy as np

from geoshade.io.paths import one_line
from geoshade.io.stores.binding import seal
from geoshade.io.stores.chunks import DamagedStoreError
from geoshade.models import Fault

#: root attributes derived from the arrays (and ``grid_store.nactive``): not used when their
#: seal does not match the arrays opened (computed from the data instead)
DERIVED = ("summaries", "distinct_codes")
#: root attributes that describe the arrays (and the ``grid_store`` layout record)
DESCRIBED = ("units", "name", "mapaxes", "step_dates", "step_seqnum", "faults", "meta")
#: the keys of ``grid_store`` that hold the binding itself (not sealed)
BINDING_KEYS = ("digest", "seals")


def _derived(attrs: dict) -> dict:
    gs = attrs.get("grid_store") if isinstance(attrs.get("grid_store"), dict) else {}
    return {**{k: attrs.get(k) for k in DERIVED}, "nactive": gs.get("nactive")}


def _described(attrs: dict) -> dict:
    gs = attrs.get("grid_store") if isinstance(attrs.get("grid_store"), dict) else {}
    return {**{k: attrs.get(k) for k in DESCRIBED},
            "grid_store": {k: v for k, v in gs.items() if k not in BINDING_KEYS}}


def sealed(attrs: dict, digest: str) -> dict:
    """``attrs`` (the root attributes of a finished store, ``grid_store`` included) with the
    arrays' ``digest`` and the two seals set in ``grid_store``.

    >>> a = sealed({"grid_store": {"nactive": 3}, "units": "METRES"}, "d")
    >>> binding(a, "d")
    (True, True, '')
    >>> a["units"] = "FEET"; binding(a, "d")[1:]
    (False, 'its attributes were changed after it was written')
    """
    gs = dict(attrs["grid_store"])
    gs.pop("seals", None)
    gs["digest"] = digest
    out = {**attrs, "grid_store": gs}
    gs["seals"] = {"derived": seal(digest, "derived", _derived(out)),
                   "described": seal(digest, "described", _described(out))}
    return out


def binding(attrs: dict, digest: str) -> tuple[bool, bool, str]:
    """``(derived_ok, described_ok, why)``: whether the derived and the describing attributes
    were sealed for the arrays of ``digest`` as they are, and why not."""
    gs = attrs.get("grid_store") if isinstance(attrs.get("grid_store"), dict) else {}
    seals = gs.get("seals")
    if not isinstance(seals, dict):
        return False, False, "written by an older geoshade, it carries no seals"
    d_ok = seals.get("derived") == seal(digest, "derived", _derived(attrs))
    s_ok = seals.get("described") == seal(digest, "described", _described(attrs))
    if d_ok and s_ok:
        return True, True, ""
    why = ("its arrays are not those it was written with" if gs.get("digest") != digest
           else "its attributes were changed after it was written")
    return d_ok, s_ok, why


def _damaged(label, name: str, what: str) -> DamagedStoreError:
    return DamagedStoreError(f"{label}: damaged '{name}' attribute ({what})")


def read_faults(raw, dims, label) -> list[Fault]:
    """The ``faults`` attribute (``[{"name": str, "faces": [[i, j, k, face], ...]}, ...]``) as
    :class:`~geoshade.models.Fault` objects, every face inside ``dims``.

    >>> read_faults([{"name": "F1", "faces": [[0, 1, 0, 3]]}], (2, 2, 1), "s.zarr")
    [Fault('F1', 1 faces)]
    >>> read_faults(5, (2, 2, 1), "s.zarr")
    Traceback (most recent call last):
    ...
    geoshade.io.stores.chunks.DamagedStoreError: s.zarr: damaged 'faults' attribute (expected a \
list of {name, faces}, got int)
    """
    if raw is None:
        return []
    if not isinstance(raw, list):
        raise _damaged(label, "faults", f"expected a list of {{name, faces}}, got "
                                        f"{type(raw).__name__}")
    out = []
    hi = np.array([*dims, 6])
    for n, f in enumerate(raw):
        if not isinstance(f, dict) or not isinstance(f.get("name"), str) \
                or not isinstance(f.get("faces"), list):
            raise _damaged(label, "faults", f"fault {n}: expected {{name: text, faces: list}}")
        try:
            faces = np.asarray(f["faces"], dtype=np.int64)
            if faces.size and (faces.ndim != 2 or faces.shape[1] != 4):
                raise ValueError(f"faces of shape {faces.shape}, expected (n, 4)")
        except (TypeError, ValueError, OverflowError) as err:
            what = str(err)[:120] if type(err) is ValueError else one_line(err)
            raise _damaged(label, "faults", f"fault {f['name'][:40]!r}: {what}") from None
        faces = faces.reshape(-1, 4)
        bad = (faces < 0).any(1) | (faces >= hi).any(1)
        if bad.any():
            raise _damaged(label, "faults", f"fault {f['name'][:40]!r}: face "
                                            f"{faces[bad][0].tolist()} is outside the grid "
                                            f"{'×'.join(map(str, dims))}")
        out.append(Fault(f["name"], faces.astype(np.int32)))
    return out


def read_mapaxes(raw, label) -> list[float] | None:
    """The ``mapaxes`` attribute: None or 6 finite numbers."""
    if raw is None:
        return None
    if not isinstance(raw, list) or len(raw) != 6 or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
            for v in raw):
        raise _damaged(label, "mapaxes", "expected null or 6 finite numbers")
    return [float(v) for v in raw]


def read_meta(raw, label) -> dict:
    """The ``meta`` attribute: an object (code names as ``{name: {code: text}}``, the code an
    integer)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise _damaged(label, "meta", f"expected an object, got {type(raw).__name__}")
    meta = dict(raw)
    try:   # code names as JSON keeps them ({"FACIES": {"0": "SHALE"}}): codes are integers
        if "codes" in meta:
            meta["codes"] = {str(n): {int(c): str(t) for c, t in d.items()}
                             for n, d in meta["codes"].items()}
    except (AttributeError, TypeError, ValueError) as err:
        raise DamagedStoreError(f"{label}: damaged 'meta' attribute: its code names "
                                f"({one_line(err)})") from None
    return meta


def read_nactive(raw, ncells: int, label) -> int | None:
    """``grid_store.nactive``: an integer from 0 to the cell count (None when absent)."""
    if raw is None:
        return None
    if not isinstance(raw, int) or isinstance(raw, bool) or not 0 <= raw <= ncells:
        raise _damaged(label, "grid_store.nactive", f"expected an integer from 0 to {ncells}, "
                                                    f"got {str(raw)[:40]}")
    return raw


def read_steps(dates, seqnum, label) -> tuple[list[str], list[int]]:
    """``step_dates`` (texts) and ``step_seqnum`` (integers, as many or none)."""
    dates = [] if dates is None else dates
    seqnum = [] if seqnum is None else seqnum
    if not isinstance(dates, list) or not all(isinstance(d, str) for d in dates):
        raise _damaged(label, "step_dates", "expected a list of dates")
    if not isinstance(seqnum, list) or not all(isinstance(v, int) and not isinstance(v, bool)
                                               for v in seqnum) \
            or (seqnum and len(seqnum) != len(dates)):
        raise _damaged(label, "step_seqnum", f"expected a list of integers, one per step "
                                             f"({len(dates)})")
    return [str(d) for d in dates], [int(v) for v in seqnum]


def read_text(raw, name: str, label) -> str:
    """A text attribute (``units``, ``name``)."""
    if raw is None:
        return ""
    if not isinstance(raw, str):
        raise _damaged(label, name, f"expected text, got {type(raw).__name__}")
    return raw


__all__ = ["DERIVED", "DESCRIBED", "binding", "read_faults", "read_mapaxes", "read_meta",
           "read_nactive", "read_steps", "read_text", "sealed"]
