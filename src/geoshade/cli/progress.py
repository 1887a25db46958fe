"""The one progress bar of the CLI: a tqdm bar (on a terminal; silent in pipes and CI) driven by
the :mod:`geoshade.progress` protocol, ``progress(done, total)``."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import tqdm

from geoshade.errors import terminal_safe
from geoshade.progress import Progress

#: what the bar counts -> how tqdm shows it
UNITS = {
    "bytes": {"unit": "B", "unit_scale": True, "unit_divisor": 1024},
    "steps": {"unit": "step"},
    "slabs": {"unit": "slab"},
    "values": {"unit": "value", "unit_scale": True},
}


@contextlib.contextmanager
def progress_bar(desc: str, unit: str = "slabs") -> Iterator[Progress]:
    """Yield a ``progress(done, total)`` callback that drives a tqdm bar; close it at the end.

    The bar appears with the first report; a report with a new ``total`` (work found on the
    way, e.g. an INCLUDE file) resizes it.

    Parameters
    ----------
    desc : str
        The bar's label.
    unit : str
        What ``done`` and ``total`` count: one of :data:`UNITS` (``bytes`` are shown as KiB,
        MiB, ...).

    Examples
    --------
    >>> with progress_bar("reading", unit="bytes") as cb:
    ...     cb(512, 1024); cb(1024, 1024)
    """
    if unit not in UNITS:
        raise ValueError(f"progress_bar: unit must be one of {', '.join(UNITS)}, got {unit!r}")
    bar = None

    def callback(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm.tqdm(total=total, desc=terminal_safe(desc), leave=False, disable=None,
                            **UNITS[unit])  # the label may hold a file's name: escaped
        elif bar.total != total:
            bar.total = total
        bar.update(done - bar.n)  # tqdm redraws at most every mininterval

    try:
        yield callback
    finally:
        if bar is not None:
            bar.close()
