"""The progress protocol: long work reports ``progress(done, total)``; adapters draw it.

A *progress callback* is any callable ``progress(done, total)`` with two ints: ``done`` units of
``total`` are finished (bytes read, report steps, slabs, values, tasks).  Every long function of
geoshade takes ``progress=None`` (no reports) or such a callable; ``io`` and ``compute`` never
draw anything themselves.  The adapters draw: the CLI's tqdm bar
(:func:`geoshade.cli.progress.progress_bar`), the viewer's status-bar widget.

The combinators here build callbacks from callbacks:

- :func:`resolve` turns ``None`` into :data:`NULL`, so a function can call it unconditionally;
- :func:`scaled` maps one stage's ``(done, total)`` into a slice of an outer total;
- :func:`stages` splits one callback into several consecutive, weighted stages;
- :class:`Counter` accumulates increments (``add(n)``) against a total that may grow
  (``grow(n)``, e.g. an INCLUDE file found while reading).

Examples
--------
>>> calls = []
>>> read, build = stages(lambda d, t: calls.append((d, t)), 75, 25)
>>> read(1, 3); read(3, 3); build(1, 5); build(5, 5)
>>> calls
[(25, 100), (75, 100), (80, 100), (100, 100)]
"""

from __future__ import annotations

from collections.abc import Callable

#: ``progress(done, total)``: ``done`` of ``total`` units finished; the return value is ignored
Progress = Callable[[int, int], object]


def _null(done: int, total: int) -> None:
    """Ignore a report."""


#: the callback that reports to nobody
NULL: Progress = _null


def resolve(progress: Progress | None) -> Progress:
    """``progress`` itself, or :data:`NULL` for ``None``.

    Raises
    ------
    TypeError
        Anything else (e.g. the old ``progress=False``): one line saying what is expected.

    Examples
    --------
    >>> resolve(None) is NULL, resolve(print) is print
    (True, True)
    >>> resolve(False)
    Traceback (most recent call last):
    ...
    TypeError: progress: expected None or a callable progress(done, total), got False
    """
    if progress is None:
        return NULL
    if not callable(progress):
        raise TypeError(f"progress: expected None or a callable progress(done, total), got "
                        f"{progress!r}")
    return progress


def scaled(progress: Progress | None, start: int, stop: int, total: int) -> Progress:
    """A callback that maps its ``(done, of)`` onto ``[start, stop]`` of ``total``.

    For multi-stage work: stage two of a job that reports 100 units in all, 40 of them for
    stage one, is ``scaled(progress, 40, 100, 100)``.  Reports are whole numbers, rounded down,
    and the stage's end is exactly ``stop``.

    Examples
    --------
    >>> calls = []
    >>> second = scaled(lambda d, t: calls.append((d, t)), 40, 100, 100)
    >>> second(0, 3); second(1, 3); second(3, 3)
    >>> calls
    [(40, 100), (60, 100), (100, 100)]
    >>> scaled(None, 0, 1, 1) is NULL
    True
    """
    cb = resolve(progress)
    if cb is NULL:
        return NULL
    start, stop, total = int(start), int(stop), int(total)
    if not 0 <= start <= stop <= total:
        raise ValueError(f"scaled: expected 0 <= start <= stop <= total, got {start}, {stop}, "
                         f"{total}")
    span = stop - start

    def report(done: int, of: int) -> None:
        of = int(of)
        part = span if of <= 0 else span * min(max(int(done), 0), of) // of
        cb(start + part, total)

    return report


def stages(progress: Progress | None, *weights: int) -> list[Progress]:
    """One callback per stage, the stages sharing ``progress`` in proportion to ``weights``.

    The outer total is ``sum(weights)``; stage ``i`` reports within its own slice (see
    :func:`scaled`), whatever its own totals are.  The weights are the outer units, so they
    also set the resolution: ``stages(p, 60, 40)`` reports in percent.

    Examples
    --------
    >>> calls = []
    >>> a, b = stages(lambda d, t: calls.append((d, t)), 10, 10)
    >>> a(5, 10); a(10, 10); b(1, 1)
    >>> calls
    [(5, 20), (10, 20), (20, 20)]
    >>> stages(None, 1, 2) == [NULL, NULL]
    True
    """
    ws = [int(w) for w in weights]
    if not ws or min(ws) < 0:
        raise ValueError(f"stages: expected one or more weights >= 0, got {weights}")
    total, out, at = sum(ws), [], 0
    for w in ws:
        out.append(scaled(progress, at, at + w, total))
        at += w
    return out


class Counter:
    """Accumulates increments and reports the running sum: ``add(n)`` -> ``progress(done, total)``.

    ``grow(n)`` raises the total (work discovered on the way; reported with the next ``add``).

    Examples
    --------
    >>> calls = []
    >>> c = Counter(lambda d, t: calls.append((d, t)), 10)
    >>> c.add(4); c.grow(5); c.add(11)
    >>> calls, c.done, c.total
    ([(4, 10), (15, 15)], 15, 15)
    >>> Counter(None, 3).add(3)  # no callback: counts quietly
    """

    def __init__(self, progress: Progress | None, total: int):
        self.progress = resolve(progress)
        self.done, self.total = 0, int(total)

    def add(self, n: int) -> None:
        """``n`` more units finished."""
        self.done += int(n)
        self.progress(self.done, self.total)

    def grow(self, n: int) -> None:
        """``n`` more units to do."""
        self.total += int(n)
