"""Names of properties and keywords, matched the same way in every part: exactly, else
case-insensitively when that is unambiguous (``swat`` finds ``SWAT``)."""

from __future__ import annotations

from collections import ChainMap
from collections.abc import Mapping
from typing import Any

import numpy as np

from geoshade.errors import InputError


def resolve_name(name, names, what: str, where: str = "", has: str = "has") -> str:
    """``name`` spelled as in ``names``, or one clear error listing them.

    >>> resolve_name("pressure", ["PRESSURE", "SGAS"], "color_by")
    'PRESSURE'
    >>> resolve_name("soil", ["SWAT"], "property", "CASE")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: CASE: property: unknown name 'soil'; it has SWAT
    """
    names = [str(n) for n in names]
    if name in names:
        return str(name)
    cands = [n for n in names if n.upper() == str(name).upper()]
    if len(cands) == 1:
        return cands[0]
    w = f"{where}: " if where else ""
    raise InputError(f"{w}{what}: unknown name {name!r}; it {has} "
                     f"{', '.join(names) or 'no names'}")


def step_names(grid) -> list[str]:
    """Names of a corner-point grid's report-step properties (empty for a static grid)."""
    if not grid.steps:
        return []
    names = grid.meta.get("step_keywords")
    return [str(n) for n in (names if names else grid.steps[0])]


#: properties a case can show without holding them: name -> (the saturations it is made of);
#: SOIL = 1 - SWAT - SGAS (three phases; 1 - SWAT with no gas) where a case has no SOIL
DERIVED = {"SOIL": ("SWAT", "SGAS")}


def derived_names(grid) -> dict[str, tuple[str, ...]]:
    """The derived properties of ``grid`` (:data:`DERIVED`) it can show: those it does not hold
    whose inputs are report-step properties, with the inputs it has.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> derived_names(synthetic_grid(3, 3, 2))
    {'SOIL': ('SWAT',)}
    """
    have = set(grid.property_names())
    dynamic = set(step_names(grid))
    out = {}
    for name, parts in DERIVED.items():
        if name not in have and parts[0] in dynamic:
            out[name] = tuple(p for p in parts if p in dynamic)
    return out


def derived_values(grid, name: str, step: int, cell=None) -> Any:
    """The (nx, ny, nz) values of derived property ``name`` at report ``step``; with ``cell``
    ((i, j, k)) the one value of that cell (only that cell of each input is read).

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(3, 3, 2)
    >>> one, every = derived_values(g, "SOIL", 1, (1, 2, 0)), derived_values(g, "SOIL", 1)
    >>> bool(one == every[1, 2, 0])
    True
    """

    parts = derived_names(grid)[name]
    if cell is not None:
        i, j, k = cell
        return 1.0 - sum(float(np.asarray(grid.steps[step][p])[i, j, k]) for p in parts)
    total = np.zeros(grid.dims, np.float64)
    for p in parts:
        total += np.asarray(grid.steps[step][p], np.float64)
    return np.asfortranarray(1.0 - total)


def grid_property(grid, name) -> str | None:
    """The grid's own spelling of property ``name`` (None stays None).

    >>> from geoshade.models import CornerPointGrid
    >>> import numpy as np
    >>> g = CornerPointGrid(np.zeros((2, 2, 6)), np.zeros((2, 2, 2)),
    ...                     properties={"PORO": np.zeros((1, 1, 1))})
    >>> grid_property(g, "poro")
    'PORO'
    """
    if name is None or name == "":
        return None
    return resolve_name(name, [*grid.property_names(), *derived_names(grid)], "property",
                        grid.name)


__all__ = ["DERIVED", "derived_names", "derived_values", "grid_property", "resolve_name",
           "step_names"]


class _Derived(Mapping):
    """Derived properties computed when they are read (``name -> make()``)."""

    def __init__(self, makers: dict):
        self._makers = makers

    def __getitem__(self, name):
        return self._makers[name]()

    def __iter__(self):
        return iter(self._makers)

    def __len__(self) -> int:
        return len(self._makers)


def properties_at(grid, k: int | None) -> Mapping:
    """Static, report-step ``k`` and derived properties (SOIL ...) as one mapping whose values
    are read (or computed) only when looked up; the static properties when the grid has no
    report steps or ``k`` is None."""
    if not grid.steps or k is None:
        return grid.properties
    derived = _Derived({n: (lambda n=n: derived_values(grid, n, k)) for n in derived_names(grid)})
    return ChainMap(grid.steps[k], grid.properties, derived)  # type: ignore[arg-type]
