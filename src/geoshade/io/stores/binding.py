"""What binds a grid store's records to the arrays they describe (issue 32: stores that cannot
lie).

A grid store keeps records *derived* from its arrays (each array's colour-scale summary, an
integer array's distinct codes, the active count, the index's faces and per-chunk statistics,
the coarse level) and records that *describe* them (faults, map axes, units, dates, names).
Each is bound to the arrays it was made from:

- the **arrays' digest**: a SHA-256 over every array's name, shape, dtype, chunks and the
  CRC-32 of each chunk — the checksum records :mod:`geoshade.io.stores.chunks` keeps, and
  checks against every chunk read — so two stores of the same size with other values have
  other digests;
- a **seal** of each record: a SHA-256 of the digest, the record's kind and the record itself
  (canonical JSON). A record copied from another store, one made before the arrays were
  replaced, or one edited afterwards no longer matches its seal and is not used: the value is
  computed from the data instead, and one line says so;
- a **sample**: where a record is used, one chunk (chosen from the digest) is computed again
  and compared with it (a summary covers the chunk's values, a code table holds its codes, the
  index's statistics, active count, values and faces of that chunk are what they say).

A writer who recomputes digest, seals and every sampled chunk can still describe other data:
a seal is a check of consistency, not a signature (there is no secret), so a store is as
trustworthy as whoever can write to it; what it stops is a record that disagrees with the
arrays drawn — copied, stale, or edited — being drawn as if it agreed.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from collections.abc import Iterable, Iterator, Mapping

import numpy as np

__all__ = ["UnboundRecordWarning", "arrays_digest", "sample_chunk", "seal"]


class UnboundRecordWarning(UserWarning):
    """A store's record that does not match the arrays it describes: not used (said once)."""


def arrays_digest(items: Iterable[tuple]) -> str:
    """The digest of a store's arrays from ``(name, shape, dtype, chunks, crcs)`` rows (any
    order): SHA-256, hex.

    Examples
    --------
    >>> a = arrays_digest([("x", (4,), "uint8", (2,), [1, 2])])
    >>> a == arrays_digest([("x", [4], "uint8", [2], [1, 2])]), len(a)
    (True, 64)
    >>> a == arrays_digest([("x", (4,), "uint8", (2,), [1, 3])])
    False
    """
    h = hashlib.sha256(b"geoshade arrays v1\0")
    for name, shape, dtype, chunks, crcs in sorted(items, key=lambda r: str(r[0])):
        head = json.dumps([str(name), [int(v) for v in shape], np.dtype(dtype).name,
                           [int(v) for v in chunks], len(crcs)], separators=(",", ":"))
        h.update(head.encode() + b"\0")
        h.update(np.asarray(crcs, dtype=np.int64).astype("<u4").tobytes())
    return h.hexdigest()


def canonical(content) -> bytes:
    """``content`` as canonical JSON (sorted keys, no spaces): what a seal is computed over.

    >>> canonical({"b": [1, 2.5], "a": None})
    b'{"a":null,"b":[1,2.5]}'
    """
    return json.dumps(content, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      default=str).encode()


def seal(digest: str, kind: str, content) -> str:
    """The seal of the record ``content`` of ``kind`` made from the arrays of ``digest``.

    >>> s = seal("d1", "summaries", {"props/P": [0.0, 1.0]})
    >>> s == seal("d1", "summaries", {"props/P": [0.0, 1.0]}), s == seal("d2", "summaries",
    ...                                                                  {"props/P": [0.0, 1.0]})
    (True, False)
    """
    h = hashlib.sha256(b"geoshade seal v1\0" + str(digest).encode() + b"\0" + kind.encode()
                       + b"\0" + canonical(content))
    return h.hexdigest()


def sample_chunk(digest: str, grid, salt: int = 0) -> tuple[int, ...]:
    """The chunk (coordinates in the chunk grid ``grid``) sampled for ``digest``: the same for a
    store every time, spread over the chunks from one store to the next.

    >>> c = sample_chunk("ab12", (4, 3, 2))
    >>> c == sample_chunk("ab12", (4, 3, 2)), len(c), all(0 <= v < n for v, n in zip(c, (4, 3, 2)))
    (True, 3, True)
    """
    n = int(np.prod(grid)) if len(grid) else 1
    h = int(hashlib.sha256(f"{digest}:{salt}".encode()).hexdigest()[:15], 16)
    return tuple(int(v) for v in np.unravel_index(h % max(1, n), tuple(grid)))


class SampledRecords(Mapping):
    """A store's per-array records (``{"props/NAME": record, "steps/KW": [record per step]}``)
    that check each record against one chunk of its array the first time it is asked for
    (:func:`sample_chunk`); a record that disagrees is missing from then on (the caller
    computes the value from the data) and one :class:`UnboundRecordWarning` says so.

    Parameters
    ----------
    records : dict
        key -> record (or list of records per step).
    arrays : dict
        key -> :class:`~geoshade.io.stores.chunks.StoreArray` of the array it describes.
    actnum : StoreArray
        The store's ACTNUM (the records are over the active cells).
    agrees : callable(record, values, active) -> str
        ``""`` when ``record`` agrees with a chunk's values and active cells, else why not.
    what : str
        What the records are, for the message (``"summary"``).
    label, digest : str
        The store as the user named it; its arrays' digest.
    """

    def __init__(self, records: dict, arrays: dict, actnum, agrees, what: str, label: str,
                 digest: str):
        self._records, self._arrays, self._actnum = dict(records), arrays, actnum
        self._agrees, self._what, self._label, self._digest = agrees, what, label, digest
        self._state: dict[str, bool] = {}

    def _check(self, key: str) -> bool:
        ok = self._state.get(key)
        if ok is not None:
            return ok
        rec, arr = self._records[key], self._arrays.get(key)
        why = ""
        if arr is not None and rec is not None:
            cc = sample_chunk(self._digest, self._actnum.grid)
            act = np.asarray(self._actnum.chunk(cc)) != 0
            if isinstance(rec, list):    # a report-step array: one step sampled
                t = sample_chunk(self._digest, (len(rec),), salt=1)[0] if rec else 0
                why = self._agrees(rec[t], np.asarray(arr.chunk((t, *cc)))[0], act) if rec \
                    else ""
                where = f"step {t}, chunk {'/'.join(map(str, cc))}"
            else:
                why = self._agrees(rec, np.asarray(arr.chunk(cc)), act)
                where = f"chunk {'/'.join(map(str, cc))}"
        self._state[key] = ok = not why
        if not ok:
            warnings.warn(f"{self._label}: the {self._what} it keeps of {key} does not match "
                          f"its data ({why} in {where}); computed from the data",
                          UnboundRecordWarning, stacklevel=3)
        return ok

    def __getitem__(self, key: str):
        if key not in self._records or not self._check(key):
            raise KeyError(key)
        return self._records[key]

    def __iter__(self) -> Iterator[str]:
        return (k for k in self._records if self._state.get(k, True))

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __repr__(self) -> str:
        return f"SampledRecords({self._what}: {sorted(self._records)})"
