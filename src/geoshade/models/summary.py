"""What a colour scale needs to know of a cell array over the active cells: a
:class:`ValueSummary`, the partial summaries of blocks (a chunk, a slab) and their exact
combination, and their JSON rows (a grid store keeps its arrays' summaries).

The compiled passes live in :mod:`geoshade.compute.grid.cell_values`; the writer of a grid store
(:mod:`geoshade.io.stores.grid_store`) takes :func:`summary_part` of each slab it holds anyway.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: cells per slab of :func:`summary_part`
SLAB_CELLS = 1 << 22


@dataclass(frozen=True)
class ValueSummary:
    """Finite and positive extremes of a property over the active cells.

    lo, hi:            finite min/max (NaN when no active cell has a finite value)
    pos_lo, pos_hi:    min/max of the finite positive values (NaN when there is none)
    nonfinite:         active cells whose value is NaN or infinite
    nonpositive:       active cells with a finite value <= 0 (no value on a log scale)
    count:             active cells
    """

    lo: float
    hi: float
    pos_lo: float
    pos_hi: float
    nonfinite: int
    nonpositive: int
    count: int

    def extremes(self, log: bool = False) -> np.ndarray:
        """The (at most two) values whose range is the property's: what
        :meth:`ColorStyle.default_range` and :meth:`ColorStyle.resolved` need to see."""
        a, b = (self.pos_lo, self.pos_hi) if log else (self.lo, self.hi)
        return np.array([a, b]) if np.isfinite(a) else np.zeros(0)

    def gaps(self, log: bool = False) -> int:
        """Active cells without a colour-scale value (log: non-positive ones too)."""
        return self.nonfinite + (self.nonpositive if log else 0)


def summary_part(values, active=None) -> np.ndarray:
    """``(7,)`` float64 partial summary of one block (a slab, a chunk) of ``values`` over its
    ``active`` cells (0/1 or bool, same shape; default all): lo, hi, pos_lo, pos_hi (±inf
    when there is none), nonfinite, nonpositive, count; numpy, k-slab by k-slab (bounded
    temporaries).  :func:`combine` joins parts exactly as one pass would.

    Examples
    --------
    >>> summary_part(np.array([[[2.0, -1.0, np.nan]]]), np.array([[[1, 1, 0]]])).tolist()
    [-1.0, 2.0, 2.0, 2.0, 0.0, 1.0, 2.0]
    """
    v = np.asarray(values)
    act = None if active is None else np.asarray(active)
    if act is not None and act.dtype != bool:  # ACTNUM as given (0/1): a mask, not indices
        act = act != 0
    if act is not None and act.shape != v.shape:
        raise ValueError(f"summary_part: active has shape {act.shape}, values {v.shape}")
    nz = v.shape[2] if v.ndim == 3 else 1
    per = max(1, int(np.prod(v.shape[:2])) if v.ndim == 3 else v.size)
    step = max(1, SLAB_CELLS // per)
    lo = pos_lo = np.inf
    hi = pos_hi = -np.inf
    nonfinite = nonpositive = count = 0
    for k0 in range(0, nz, step):  # slabs of layers, not cells
        s = v[:, :, k0:k0 + step] if v.ndim == 3 else v
        if act is not None:
            s = s[act[:, :, k0:k0 + step] if v.ndim == 3 else act]
        s = np.asarray(s).ravel()
        count += s.size
        fin = np.isfinite(s)
        nf = int(np.count_nonzero(fin))
        nonfinite += s.size - nf
        if nf:
            f = s[fin] if nf < s.size else s
            lo, hi = min(lo, float(f.min())), max(hi, float(f.max()))
            pos = f[f > 0]
            nonpositive += f.size - pos.size
            if pos.size:
                pos_lo, pos_hi = min(pos_lo, float(pos.min())), max(pos_hi, float(pos.max()))
    return np.array([lo, hi, pos_lo, pos_hi, nonfinite, nonpositive, count], np.float64)


def combine(parts) -> ValueSummary:
    """One :class:`ValueSummary` from :func:`summary_part` rows ((m, 7), or a list of them):
    extremes of the extremes, sums of the counts (exact: the same as one pass)."""
    p = np.asarray(parts, np.float64).reshape(-1, 7)
    nan = float("nan")
    if not len(p):
        return ValueSummary(nan, nan, nan, nan, 0, 0, 0)
    lo, hi = float(p[:, 0].min()), float(p[:, 1].max())
    plo, phi = float(p[:, 2].min()), float(p[:, 3].max())
    return ValueSummary(lo if lo <= hi else nan, hi if lo <= hi else nan,
                        plo if plo <= phi else nan, phi if plo <= phi else nan,
                        int(p[:, 4].sum()), int(p[:, 5].sum()), int(p[:, 6].sum()))


class SummaryCheck:
    """Whether a stored :class:`ValueSummary` of a whole array agrees with one block of it
    (a grid store samples a chunk, :mod:`geoshade.io.stores.binding`): the block's values lie
    within its extremes, its counts are within the summary's, and the summary counts
    ``nactive`` cells where that is known.  Called with ``(summary, values, active)``; ``""``
    when they agree, else why not.

    >>> s = combine(summary_part(np.array([[[1.0, 5.0, 3.0]]])))
    >>> SummaryCheck(3)(s, np.array([[[5.0]]]), np.array([[[1]]]))
    ''
    >>> SummaryCheck(3)(s, np.array([[[7.0]]]), np.array([[[1]]]))
    'values up to 7 beyond its maximum 5'
    """

    def __init__(self, nactive: int | None = None):
        self.nactive = nactive

    def __call__(self, s: ValueSummary, values, active) -> str:
        lo, hi, plo, phi, nonfinite, nonpositive, count = summary_part(values, active)
        if self.nactive is not None and s.count != self.nactive:
            return f"it counts {s.count} active cells of {self.nactive}"
        if count > s.count or nonfinite > s.nonfinite or nonpositive > s.nonpositive:
            return "more cells than it counts"
        for a, b, name in ((lo, hi, ""), (plo, phi, "positive ")):
            if np.isfinite(a):
                slo, shi = (s.lo, s.hi) if not name else (s.pos_lo, s.pos_hi)
                if not slo <= a:
                    return f"{name}values down to {a:.6g} below its minimum {slo:.6g}"
                if not b <= shi:
                    return f"{name}values up to {b:.6g} beyond its maximum {shi:.6g}"
        return ""


def part_to_json(part) -> list:
    """A :func:`summary_part` row as JSON numbers (±inf as None: JSON has no infinities)."""
    return [float(x) if np.isfinite(x) else None for x in np.asarray(part, np.float64)[:4]] \
        + [int(x) for x in np.asarray(part)[4:7]]


def part_from_json(row) -> np.ndarray:
    """The inverse of :func:`part_to_json` (None: +inf for a minimum, -inf for a maximum)."""
    if not isinstance(row, (list, tuple)) or len(row) != 7:
        raise ValueError(f"expected 7 numbers, got {row!r}")
    fill = (np.inf, -np.inf, np.inf, -np.inf)
    return np.array([fill[i] if row[i] is None else float(row[i]) for i in range(4)]
                    + [float(int(x)) for x in row[4:]], np.float64)


def summary_to_json(s: ValueSummary) -> list:
    """A :class:`ValueSummary` as the row :func:`part_from_json` reads (NaN extremes: None)."""
    return [None if not np.isfinite(x) else float(x) for x in (s.lo, s.hi, s.pos_lo,
                                                                s.pos_hi)] \
        + [int(s.nonfinite), int(s.nonpositive), int(s.count)]


def summary_from_json(row) -> ValueSummary:
    """A :class:`ValueSummary` from :func:`summary_to_json`'s row (raises ValueError)."""
    return combine(part_from_json(row))


def slab_summaries(slabs: list, steps: dict, props: list) -> dict | None:
    """A grid store's summaries (``{"props/NAME": row, "steps/KW": [row per step]}``, rows of
    :func:`summary_to_json`) combined from its slabs' ``{name: part row or [row per step]}``
    (``steps``: step array name -> number of steps); None when a slab has none (an ingest
    resumed from slabs an older version wrote).

    >>> one = {"props/P": [0.0, 1.0, 1.0, 1.0, 0, 1, 2]}
    >>> slab_summaries([one, {"props/P": [None, None, None, None, 3, 0, 3]}], {}, ["props/P"])
    {'props/P': [0.0, 1.0, 1.0, 1.0, 3, 1, 5]}
    """
    if not slabs or any(d is None for d in slabs):
        return None
    out: dict = {}
    for name in props:
        out[name] = summary_to_json(combine([part_from_json(d[name]) for d in slabs]))
    for name, nt in steps.items():
        out[name] = [summary_to_json(combine([part_from_json(d[name][t]) for d in slabs]))
                     for t in range(nt)]
    return out


def _attribute(raw) -> dict:
    """A store attribute that is an object (``{}`` where it is absent: an older store)."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise ValueError(f"expected an object, got {type(raw).__name__}")
    return raw


def read_summaries(raw, props: list, kws: list, nt: int) -> dict:
    """A grid store's ``summaries`` attribute (:func:`slab_summaries`) as ``{"props/NAME":
    ValueSummary, "steps/KW": [ValueSummary per step]}`` for the store's properties and
    report-step keywords; ``{}`` for None (a store written before summaries were kept).

    Raises
    ------
    ValueError, TypeError
        A damaged attribute (the caller names the store).
    """
    raw = _attribute(raw)
    out: dict = {}
    for n in props:
        if f"props/{n}" in raw:
            out[f"props/{n}"] = summary_from_json(raw[f"props/{n}"])
    for kw in kws:
        if f"steps/{kw}" in raw:
            rows = raw[f"steps/{kw}"]
            if not isinstance(rows, list) or len(rows) != nt:
                raise ValueError(f"steps/{kw}: expected {nt} rows")
            out[f"steps/{kw}"] = [summary_from_json(r) for r in rows]
    return out


#: a grid store keeps the distinct values of an integer array up to this many (more: none)
STORED_CODES = 4096


def codes_part(values, active=None, limit: int = STORED_CODES) -> list | None:
    """The distinct values of the integer block ``values`` over its ``active`` cells (0/1 or
    bool, same shape; default all), sorted, as a JSON list; None when there are more than
    ``limit`` (a grid store keeps the codes of its integer arrays: a region or facies property
    is drawn as categories without a pass over it).  Counting, not sorting, where the values
    span a small range.

    >>> codes_part(np.array([[[3, 1, 3, 7]]]), np.array([[[1, 1, 1, 0]]]))
    [1, 3]
    >>> codes_part(np.arange(10).reshape(1, 1, 10), limit=4) is None
    True
    """
    v = np.asarray(values)
    if active is not None:
        v = v[np.asarray(active) != 0]
    v = v.ravel()
    if not v.size:
        return []
    lo, hi = int(v.min()), int(v.max())
    if hi - lo < 1 << 20:   # a small span: one count per value (no sort)
        u = np.flatnonzero(np.bincount((v - lo).astype(np.int64), minlength=1)) + lo
    else:
        u = np.unique(v)
    return None if u.size > limit else [int(x) for x in u]


def merge_codes(parts, limit: int = STORED_CODES) -> list | None:
    """The codes of a whole array from its blocks' :func:`codes_part` (None when a block has
    too many, or the union is more than ``limit``).

    >>> merge_codes([[1, 3], [2, 3]]), merge_codes([[1], None])
    ([1, 2, 3], None)
    """
    parts = list(parts)
    if any(p is None for p in parts):
        return None
    u = sorted(set().union(*map(set, parts)))
    return None if len(u) > limit else u


def read_codes(raw, props: list) -> dict:
    """A grid store's ``distinct_codes`` attribute (``{"props/NAME": [int, ...] or None}``) as
    ``{"props/NAME": float64 array or None}`` for the store's properties; ``{}`` for None (a
    store written before codes were kept).

    Raises
    ------
    ValueError, TypeError
        A damaged attribute (the caller names the store).

    >>> read_codes({"props/F": [1, 2]}, ["F"])["props/F"].tolist()
    [1.0, 2.0]
    """
    raw = _attribute(raw)
    out: dict = {}
    for n in props:
        row = raw.get(f"props/{n}", False)
        if row is False:
            continue
        if row is not None and (not isinstance(row, list)
                                or not all(isinstance(x, int) for x in row)):
            raise ValueError(f"props/{n}: expected a list of integers or null")
        out[f"props/{n}"] = None if row is None else np.asarray(row, np.float64)
    return out


def codes_agree(codes, values, active) -> str:
    """Whether a stored code table (float array, or None: more codes than kept) holds every
    code of one block's active cells: ``""``, else why not (see :class:`SummaryCheck`).

    >>> codes_agree(np.array([1.0, 2.0]), np.array([[[2, 3]]]), np.array([[[1, 1]]]))
    'code 3 is not in it'
    """
    if codes is None:
        return ""
    part = codes_part(values, active, limit=1 << 62)
    missing = sorted(set(part or ()) - set(np.asarray(codes).tolist()))
    return f"code {missing[0]} is not in it" if missing else ""
