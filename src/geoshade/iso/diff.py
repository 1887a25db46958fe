"""The change of a field between two steps (``diff``): ``FIELD(step) − FIELD(STEP)`` as a field
of its own, whose isosurface the View draws (e.g. ΔSWAT = 0.2).

The difference is taken node by node in float64 from the values as read and kept as float32,
as every field is drawn; inactive nodes stay inactive (the field's ``active`` mask is kept) and
a NaN at either step is a NaN in the change, so the surface is open there as it is on the
field itself. The report-step quantities the surface can be coloured by are differenced too
(ΔPRESSURE, drawn on a diverging colour map centred on 0); static ones (PORO, FIPNUM) are kept
as they are. Steps are read lazily: the step the change is taken from once, each shown step
when it is shown.

>>> import numpy as np
>>> from geoshade.models.field import FieldSeries
>>> f = FieldSeries(np.arange(3 * 8, dtype=np.float32).reshape(3, 2, 2, 2), name="SWAT")
>>> d = difference_field(f, 0)
>>> d.name, d.nsteps, d.step(2).ravel().tolist()
('ΔSWAT', 3, [16.0, 16.0, 16.0, 16.0, 16.0, 16.0, 16.0, 16.0])
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from geoshade.errors import InputError
from geoshade.models.field import FieldSeries
from geoshade.models.names import derived_names, step_names
from geoshade.models.steps import step_label, step_name
from geoshade.models.units import value_unit

#: the sign a difference's quantity is named with (ΔSWAT)
DELTA = "Δ"


class DiffSteps(Sequence):
    """``(T, nz, ny, nx)`` view of ``read(k) − read(base)``, float32, computed in float64 when
    step ``k`` is indexed (the base step is read once, here).

    >>> import numpy as np
    >>> s = DiffSteps(lambda k: np.full((2, 2, 2), k * 0.5, np.float32), 3, 1)
    >>> s.shape, float(s[2][0, 0, 0]), float(s[0][0, 0, 0])
    ((3, 2, 2, 2), 0.5, -0.5)
    """

    def __init__(self, read, nsteps: int, base: int):
        self._read = read
        self.base = int(base)
        self._then = np.asarray(read(self.base), np.float32)
        self.shape = (int(nsteps), *self._then.shape)

    def __len__(self) -> int:
        return self.shape[0]

    def __getitem__(self, k):
        now = np.asarray(self._read(int(k)), np.float32)
        return np.subtract(now, self._then, dtype=np.float64).astype(np.float32)


def keyword_of(field: FieldSeries) -> str:
    """The quantity a field shows, as its file names it (``SWAT``)."""
    return str((field.meta or {}).get("keyword") or field.name or "the field")


def check_diff_field(field: FieldSeries) -> None:
    """Refuse, in one line naming the keyword, a field a change cannot be taken of: a static
    keyword (the INIT file's, the same at every report step) or a field of one step.

    >>> import numpy as np
    >>> check_diff_field(FieldSeries(np.zeros((3, 3, 3)), name="SWAT", source="s.npy"))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: diff: SWAT of s.npy has one step; a difference needs two \
(a (time, z, y, x) field or a case with report steps)
    """
    if field.nsteps > 1:
        return
    kw = keyword_of(field)
    grid = field.grid
    if grid is not None and grid.steps and kw not in {*step_names(grid), *derived_names(grid)}:
        moving = [*step_names(grid), *derived_names(grid)]
        raise InputError(f"diff: {kw} is a static keyword (the same at every report step); a "
                         f"difference needs one that changes, such as "
                         f"{', '.join(moving[:4]) or 'SWAT'} (--keyword)")
    where = f" of {field.source}" if field.source else ""
    if grid is not None and not grid.steps:
        raise InputError(f"diff: {kw}{where}: the case has no report steps (no restart file); "
                         "a difference needs two")
    raise InputError(f"diff: {kw}{where} has one step; a difference needs two (a (time, z, y, "
                     "x) field or a case with report steps)")


def difference_field(field: FieldSeries, base: int) -> FieldSeries:
    """``field`` minus its step ``base`` (an index, resolved by the options), every step; the
    report-step properties likewise (``meta["differenced"]`` names them), static ones kept.
    ``meta["diff"]`` is ``base``; the unit is the field's."""
    check_diff_field(field)
    base = field.check_step(base)
    n = field.nsteps
    props, changed = {}, []
    for name in field.properties:
        if len(field.properties[name]) == n:   # one value per step: its change too
            props[name] = DiffSteps(lambda k, name=name: field.property_step(name, k), n, base)
            changed.append(name)
        else:
            props[name] = field.properties[name]
    meta = {**(field.meta or {}), "diff": base, "differenced": changed}
    return dataclasses.replace(field, values=DiffSteps(field.step, n, base),
                               name=DELTA + (field.name or keyword_of(field)),
                               unit=value_unit(field, field.name), properties=props, meta=meta)


def assumed_level(vmin, vmax) -> float:
    """The level of a change where none was given: half the largest change, on the side it
    lies, to two digits (``ΔSWAT`` from −0.1 to 0.6: 0.3), so the surface shows where the
    field moved most.

    >>> assumed_level(-0.1, 0.6), assumed_level(-0.8, 0.2), assumed_level(0, 0.6738)
    (0.3, -0.4, 0.34)
    >>> assumed_level(None, None)
    0.0
    """
    if vmin is None or vmax is None:
        return 0.0
    lo, hi = float(vmin), float(vmax)
    return float(f"{0.5 * (hi if abs(hi) >= abs(lo) else lo):.2g}")   # 2 digits: a level to read


def steps_text(field: FieldSeries, step: int, base: int) -> str:
    """``"2003-01-01 − 2000-01-01"``: the two steps of a change by their shortest names."""
    reports = (field.meta or {}).get("reports") or ()
    return (f"{step_name(step, field.times, reports)} − "
            f"{step_name(base, field.times, reports)}")


def diff_stats(field: FieldSeries, step: int, base: int) -> dict:
    """The stats of a change: both steps (``step``, ``from``), their dates (None where the
    field has none) and labels.

    >>> import numpy as np
    >>> f = FieldSeries(np.zeros((2, 2, 2, 2)), times=["2000-01-01", "2000-02-01"])
    >>> diff_stats(f, 1, 0)["dates"]
    ['2000-02-01', '2000-01-01']
    """
    reports = (field.meta or {}).get("reports") or ()
    dates = [None if not field.times[k] or str(field.times[k]).startswith("step ")
             else str(field.times[k]) for k in (step, base)]
    return {"step": int(step), "from": int(base), "dates": dates,
            "labels": [step_label(k, field.times, reports) for k in (step, base)]}


__all__ = ["DELTA", "DiffSteps", "assumed_level", "check_diff_field", "diff_stats",
           "difference_field", "keyword_of", "steps_text"]
