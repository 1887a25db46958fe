"""Progress bars for long work (tqdm, shown on a terminal, silent in pipes and CI)."""

from __future__ import annotations

import contextlib


@contextlib.contextmanager
def progress_bar(desc: str):
    """Yield a ``callback(done, total)`` that drives a tqdm bar; closes it at the end."""
    from tqdm import tqdm

    bar = None

    def callback(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, desc=desc, unit="slab", leave=False, disable=None)
        bar.n = done
        bar.refresh()

    try:
        yield callback
    finally:
        if bar is not None:
            bar.close()
