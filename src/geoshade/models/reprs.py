"""Short text of the models for ``repr()`` and ``print()``, like xarray's: the kind and name on
the first line, then one aligned line per item (sizes, bounds, properties, steps), never the
arrays (a grid's repr was ~10 kB of numbers). Nothing is read that is not in memory already:
a lazy array (memmap, dask, a grid store) is described by its shape and dtype, and a huge grid's
bounds come from its pillars, not its corner depths.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

#: at most this many names on a line ("... and N more" after)
MAX_NAMES = 8
#: grids with at most this many corner depths in memory get exact bounds (else the pillars')
EXACT_BOUNDS = 10_000_000


def block(kind: str, name: str, rows: Iterable[tuple[str, str]]) -> str:
    """``<kind 'name'>`` and the ``rows`` (label, text) aligned under it; empty texts dropped.

    >>> print(block("VoxelVolume", "a.raw", [("Dimensions", "x: 2, y: 3"), ("Unit", "")]))
    <VoxelVolume 'a.raw'>
    Dimensions:  x: 2, y: 3
    """
    head = f"<{kind} {name!r}>" if name else f"<{kind}>"
    rows = [(k, v) for k, v in rows if v]
    width = max((len(k) for k, _ in rows), default=0) + 2
    return "\n".join([head, *(f"{k + ':':<{width}} {v}" for k, v in rows)])


def count(n: int) -> str:
    """``1,234`` (thousands separated).

    >>> count(35820)
    '35,820'
    """
    return f"{int(n):,}"


def num(v: float) -> str:
    """A coordinate as short text (``456000``, ``1.5``, ``1.2e-05``)."""
    v = float(v)
    return f"{v:.6g}" if v != int(v) or abs(v) >= 1e15 else str(int(v))


def span(lo, hi, axes=("x", "y", "z"), unit: str = "") -> str:
    """``x 0–10, y 0–8, z 0–3 m`` from (3,) min and max.

    >>> span([0, 0, 1500.5], [10, 8, 1600])
    'x 0–10, y 0–8, z 1500.5–1600'
    """
    text = ", ".join(f"{a} {num(a0)}–{num(a1)}" for a, a0, a1 in zip(axes, lo, hi, strict=True))
    return f"{text} {unit}".rstrip()


def names(items, typed: dict | None = None) -> str:
    """``A, B, C`` (at most :data:`MAX_NAMES`, then ``… (+N)``); ``typed``: name -> dtype text.

    >>> names(["PORO", "PERMX"], {"PORO": "float32"})
    'PORO float32, PERMX'
    """
    items = [str(n) for n in items]
    shown = [f"{n} {typed[n]}" if typed and typed.get(n) else n for n in items[:MAX_NAMES]]
    more = f" … (+{len(items) - MAX_NAMES})" if len(items) > MAX_NAMES else ""
    return ", ".join(shown) + more


def array_kind(a) -> str:
    """``uint16`` plus what holds it when not a plain in-memory numpy array (``memmap``,
    ``dask``, ``zarr``) and a non-native byte order (``big-endian``).

    >>> array_kind(np.zeros(2, ">u2"))
    'uint16 (big-endian)'
    """
    dt = np.dtype(getattr(a, "dtype", "float64"))
    notes = []
    if isinstance(a, np.memmap):
        notes.append("memmap")
    elif not isinstance(a, np.ndarray):
        notes.append(type(a).__module__.split(".")[0])
    if dt.byteorder == (">" if np.little_endian else "<"):
        notes.append("big-endian" if dt.byteorder == ">" else "little-endian")
    return dt.name + (f" ({', '.join(notes)})" if notes else "")


def dtype_name(a) -> str:
    dt = getattr(a, "dtype", None)
    return np.dtype(dt).name if dt is not None else type(a).__name__


def steps_text(n: int, labels) -> str:
    """``37 (2000-01-01 … 2003-01-01)``, or ``""`` when there are none."""
    if not n:
        return ""
    labels = [str(t) for t in (labels or []) if str(t)]
    if not labels:
        return str(n)
    return f"{n} ({labels[0]})" if len(labels) == 1 else f"{n} ({labels[0]} … {labels[-1]})"


def points_text(points, depth: bool = True) -> str:
    """``12 points, x 0–10, y 0–3, depth 1500–1700`` of an (n, 3) array."""
    p = np.asarray(points, float).reshape(-1, 3)
    if not len(p):
        return "no points"
    return (f"{count(len(p))} points, "
            + span(p.min(axis=0), p.max(axis=0), ("x", "y", "depth" if depth else "z")))


__all__ = ["EXACT_BOUNDS", "MAX_NAMES", "array_kind", "block", "count", "dtype_name", "names",
           "num", "points_text", "span", "steps_text"]
