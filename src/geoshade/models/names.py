"""Names of properties and keywords, matched the same way in every part: exactly, else
case-insensitively when that is unambiguous (``swat`` finds ``SWAT``)."""

from __future__ import annotations

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
    return resolve_name(name, grid.property_names(), "property", grid.name)


__all__ = ["grid_property", "resolve_name", "step_names"]
