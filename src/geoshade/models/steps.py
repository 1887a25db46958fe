"""Time steps, named the same way in every part.

A step is given as

- an index ``0..T-1``; negative counts from the end (``-1`` is the last step);
- ``"first"`` or ``"last"``;
- a report number: ``"R36"``, ``"report 36"`` or ``"report:36"`` (the ``SEQNUM`` of an ECLIPSE
  restart; a field without report numbers refuses it);
- a date ``"YYYY-MM-DD"`` (or a :class:`datetime.date`), which must be one of the steps' dates;
  where several steps fall on that date (hourly report steps) the time is needed too:
  ``"YYYY-MM-DD HH:MM"`` or ``"YYYY-MM-DDTHH:MM[:SS]"`` (or a :class:`datetime.datetime`), and a
  date alone is refused with the steps it names listed.  Step dates with a time of day are
  ``"YYYY-MM-DD HH:MM"``.

The default everywhere is the last step (:data:`DEFAULT_STEP`): the state a simulation reached.

>>> resolve_step(None, 5)
4
>>> resolve_step("R20", 3, reports=[0, 10, 20])
2
>>> resolve_step("2001-06-01", 2, dates=["2000-01-01", "2001-06-01"])
1
>>> step_label(1, ["2000-01-01", "2001-06-01"], [0, 10])
'step 1 (report 10, 2001-06-01)'
>>> hourly = ["2015-01-01 00:00", "2015-01-01 06:00", "2015-01-01 12:00"]
>>> resolve_step("2015-01-01T06:00", 3, dates=hourly)
1
>>> resolve_step("2015-01-01", 3, dates=hourly)
Traceback (most recent call last):
...
geoshade.errors.InputError: step 2015-01-01: 3 steps have that date (steps 0 (00:00), 1 (06:00), \
2 (12:00)); give the time too, e.g. '2015-01-01 00:00', or an index
"""

from __future__ import annotations

import datetime
import re

import numpy as np

from geoshade.errors import InputError

#: the step every part shows when none is given: the last one
DEFAULT_STEP = -1

_REPORT = re.compile(r"^\s*(?:r|report)\s*[:= ]?\s*(\d+)\s*$", re.IGNORECASE)
_DATE = re.compile(r"^\s*(\d{4})-(\d{1,2})-(\d{1,2})"
                   r"(?:[ T](\d{1,2}):(\d{2})(?::(\d{2})(?:\.\d*)?)?)?\s*$")
_INT = re.compile(r"^\s*[-+]?\d+\s*$")


def _where(where: str) -> str:
    return f"{where}: " if where else ""


def _span(n: int) -> str:
    return f"{n} step{'s' if n != 1 else ''}" + (f" (0..{n - 1}, or -1 for the last)" if n else "")


def resolve_step(step, n: int, dates=(), reports=(), where: str = "",
                 default: int = DEFAULT_STEP) -> int:
    """The 0-based index of ``step`` among ``n`` steps, or one clear error.

    Parameters
    ----------
    step : None, int, str or datetime.date
        See the module's description; None gives ``default``.
    n : int
        Number of steps.
    dates : sequence of str
        ISO date of each step ("" where unknown).
    reports : sequence of int
        Report number of each step (empty when the source has none).
    where : str
        The file or model, for messages.

    Examples
    --------
    >>> resolve_step(-1, 3), resolve_step("first", 3), resolve_step(" 2 ", 3)
    (2, 0, 2)
    >>> resolve_step(3, 3, where="CASE.UNRST")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: CASE.UNRST: step 3 does not exist; there are 3 steps (0..2, or \
-1 for the last)
    """
    w = _where(where)
    if n <= 0:
        raise InputError(f"{w}step {step}: there are no time steps here (static values only)")
    if step is None:
        step = default
    if isinstance(step, datetime.datetime):
        t = step.time()
        return _by_date(step.date().isoformat(), n, dates, w,
                        None if t == datetime.time() else (t.hour, t.minute, t.second))
    if isinstance(step, datetime.date):
        return _by_date(step.isoformat(), n, dates, w)
    if isinstance(step, bool):
        raise InputError(f"{w}step: expected an index, a report number or a date, got {step!r}")
    if isinstance(step, int | np.integer):
        k = int(step)
    elif isinstance(step, float) and float(step).is_integer():
        k = int(step)
    elif isinstance(step, str):
        s = step.strip()
        if s.lower() in ("last", "first"):
            return n - 1 if s.lower() == "last" else 0
        if _INT.match(s):
            k = int(s)
        elif (m := _REPORT.match(s)) is not None:
            return _by_report(int(m.group(1)), n, reports, w)
        elif (m := _DATE.match(s)) is not None:
            y, mo, d = (int(v) for v in m.groups()[:3])
            clock = None if m[4] is None else (int(m[4]), int(m[5]), int(m[6] or 0))
            return _by_date(f"{y:04d}-{mo:02d}-{d:02d}", n, dates, w, clock)
        else:
            raise InputError(f"{w}step: {step!r} is not a step; expected an index (0, 1, ... or "
                             "-1 for the last), a report number such as R36, or a date "
                             "YYYY-MM-DD")
    else:
        raise InputError(f"{w}step: expected an index, a report number or a date, got "
                         f"{type(step).__name__}")
    if not -n <= k < n:
        raise InputError(f"{w}step {k} does not exist; there are {_span(n)}")
    return k % n


def _by_report(r: int, n: int, reports, w: str) -> int:
    reports = [int(v) for v in (reports or ())]
    if len(reports) != n:
        raise InputError(f"{w}step R{r}: the steps have no report numbers here; give an index "
                         f"(0..{n - 1}) or a date")
    if r not in reports:
        shown = ", ".join(str(v) for v in reports[:12]) + (" …" if n > 12 else "")
        raise InputError(f"{w}step R{r}: no report step has number {r}; the reports are {shown}")
    return reports.index(r)


def _split(label: str) -> tuple[str, tuple[int, int, int] | None]:
    """("YYYY-MM-DD", (h, m, s) or None) of a step's date label."""
    m = _DATE.match(label)
    if m is None:
        return label, None
    day = "{:04d}-{:02d}-{:02d}".format(*(int(v) for v in m.groups()[:3]))
    return day, None if m[4] is None else (int(m[4]), int(m[5]), int(m[6] or 0))


def _by_date(d: str, n: int, dates, w: str, clock: tuple[int, int, int] | None = None) -> int:
    dates = [str(v) for v in (dates or ())]
    known = [x for x in dates if x]
    if len(dates) != n or not known:
        raise InputError(f"{w}step {d}: the steps have no dates here; give an index "
                         f"(0..{n - 1})")
    parts = [_split(x) for x in dates]
    same = [k for k, (day, _) in enumerate(parts) if day == d]
    asked = d if clock is None else f"{d} {clock[0]:02d}:{clock[1]:02d}" + (
        f":{clock[2]:02d}" if clock[2] else "")
    if clock is not None:
        at = [k for k in same if (parts[k][1] or (0, 0, 0)) == clock
              or (parts[k][1] is not None and clock[2] == 0
                  and parts[k][1][:2] == clock[:2])]  # type: ignore[index]
        if len(at) == 1:
            return at[0]
        if not at and same:
            raise InputError(f"{w}step {asked}: no step at that time; {_several(same, dates)}")
        if len(at) > 1:
            raise InputError(f"{w}step {asked}: {_several(at, dates)}; give an index")
    elif len(same) == 1:
        return same[0]
    elif len(same) > 1:
        first = dates[same[0]]
        raise InputError(f"{w}step {d}: {len(same)} steps have that date "
                         f"({_several(same, dates)}); give the time too, e.g. {first!r}, or "
                         "an index")
    raise InputError(f"{w}step {asked}: no step has that date; the steps run from {known[0]} to "
                     f"{known[-1]} ({len(known)} dates)")


def _several(ks: list[int], dates: list[str]) -> str:
    """``steps 3..26 at 00:00 … 23:00`` (or each listed when they are few)."""
    times = [dates[k].split(" ", 1)[1] if " " in dates[k] else dates[k] for k in ks]
    if len(ks) <= 4:
        return "steps " + ", ".join(f"{k} ({t})" for k, t in zip(ks, times, strict=True))
    span = f"{ks[0]}..{ks[-1]}" if ks == list(range(ks[0], ks[-1] + 1)) else \
        ", ".join(map(str, ks[:3])) + ", …"
    return f"steps {span} at {times[0]} … {times[-1]}"


def step_label(k: int, dates=(), reports=()) -> str:
    """``"step K (report R, DATE)"`` with what is known of step ``k``."""
    extra = []
    if reports is not None and len(reports) > k:
        extra.append(f"report {int(reports[k])}")
    if dates is not None and len(dates) > k and dates[k] and not str(dates[k]).startswith("step "):
        extra.append(str(dates[k]))
    return f"step {k}" + (f" ({', '.join(extra)})" if extra else "")


def step_name(k: int, dates=(), reports=()) -> str:
    """The shortest name of step ``k`` a reader knows it by: its date, else its report number,
    else its index.

    >>> step_name(1, ["2000-01-01", "2000-02-01"]), step_name(1, (), [0, 10]), step_name(3)
    ('2000-02-01', 'report 10', 'step 3')
    """
    if dates is not None and len(dates) > k and dates[k] and not str(dates[k]).startswith("step "):
        return str(dates[k])
    if reports is not None and len(reports) > k:
        return f"report {int(reports[k])}"
    return f"step {k}"


def step_caption(k: int, n: int, dates=(), reports=()) -> str:
    """``"step K of N · report R · DATE"`` for a picture's subtitle (what is known of it).

    >>> step_caption(2, 3, ["2000-01-01", "2000-02-01", "2000-03-01"], [0, 10, 20])
    'step 2 of 3 · report 20 · 2000-03-01'
    """
    parts = [f"step {k} of {n}"]
    if reports is not None and len(reports) > k:
        parts.append(f"report {int(reports[k])}")
    if dates is not None and len(dates) > k and dates[k] and not str(dates[k]).startswith("step "):
        parts.append(str(dates[k]))
    return " · ".join(parts)


def dated_steps(model) -> tuple[list[str], list[int] | None]:
    """The dates of a model's report steps ("" where unknown) and their report numbers (None:
    unknown): a grid's ``step_dates`` and ``meta["unrst_seqnum"]``, a field's ``times`` and
    ``meta["reports"]`` -- what a summary cursor follows.

    >>> from types import SimpleNamespace
    >>> dated_steps(SimpleNamespace(step_dates=["2000-01-01", ""], meta={"unrst_seqnum": [0, 3]}))
    (['2000-01-01', ''], [0, 3])
    """
    dates = getattr(model, "step_dates", None)
    if dates is None:
        dates = getattr(model, "times", None)
    dates = [str(d) if d else "" for d in (dates or ())]
    meta = getattr(model, "meta", None) or {}
    seq = meta.get("unrst_seqnum")
    if seq is None:
        seq = meta.get("reports")
    reports = [int(r) for r in seq] if seq is not None and len(seq) == len(dates) else None
    return dates, reports


__all__ = ["DEFAULT_STEP", "dated_steps", "resolve_step", "step_caption", "step_label",
           "step_name"]
