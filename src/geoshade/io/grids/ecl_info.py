"""What ``geoshade info`` adds for an ECLIPSE/OPM grid: its local grid refinements, its media,
the reader's notes, and bounds over the active cells.

:func:`describe_case_parts` gives the keys :func:`geoshade.io.describe.describe_grid` merges
into its dict, :func:`format_case_parts` the lines :func:`geoshade.io.describe.
format_grid_description` prints for them.  Bounds come from the active cells only
(:meth:`~geoshade.models.CornerPointGrid.active_bounds`): ECLIPSE writes 0 for the corners of
inactive cells, which would stretch the depth range to 0.
"""

from __future__ import annotations

import numpy as np

from geoshade.io.grids.lgr import describe_refinements, format_refinements

__all__ = ["describe_case_parts", "format_case_parts"]


def describe_case_parts(grid) -> dict:
    """``lgrs`` (:func:`~geoshade.io.grids.lgr.describe_refinements`), ``media`` (names; empty
    for one medium), ``medium`` (the one shown), ``dual`` ("dual porosity", "dual
    permeability" or ""), ``notes`` (the reader's, e.g. which files would add properties) and,
    for a grid in memory, ``bounds`` over the active cells.

    Examples
    --------
    >>> from geoshade.models import CornerPointGrid
    >>> coord = np.array([[[x, 0, 0, x, 0, 1], [x, 1, 0, x, 1, 1]] for x in (0, 1, 2)], float)
    >>> zc = np.zeros((4, 2, 2), np.float32); zc[:2, :, 0] = 100; zc[:2, :, 1] = 110
    >>> g = CornerPointGrid(coord, zc, actnum=np.array([1, 0]).reshape(2, 1, 1))
    >>> describe_case_parts(g)["bounds"]
    [[0.0, 0.0, 100.0], [1.0, 1.0, 110.0]]
    """
    meta = grid.meta if isinstance(grid.meta, dict) else {}
    d: dict = {"lgrs": describe_refinements(grid), "media": list(getattr(grid, "media", ())),
               "medium": getattr(grid, "medium", ""), "dual": meta.get("dual", ""),
               "notes": [str(n) for n in meta.get("notes") or ()]}
    if isinstance(grid.zcorn, np.ndarray):
        d["bounds"] = [[float(v) for v in row] for row in grid.active_bounds()]
    return d


def format_case_parts(d: dict) -> list[str]:
    """``info``'s lines for the keys of :func:`describe_case_parts` (none when it has none).

    Examples
    --------
    >>> format_case_parts({"media": ["matrix", "fracture"], "medium": "matrix",
    ...                    "dual": "dual porosity", "notes": ["grid file alone"]})
    ['  media    dual porosity: matrix, fracture (showing the matrix; --medium fracture)', \
'  note     grid file alone']
    """
    lines = format_refinements(d.get("lgrs"))
    media = d.get("media") or []
    if media:
        other = next((m for m in media if m != d.get("medium")), "")
        lines.append(f"  media    {d.get('dual') or 'dual porosity'}: {', '.join(media)} "
                     f"(showing the {d.get('medium')}" + (f"; --medium {other})" if other
                                                         else ")"))
    lines += [f"  note     {n}" for n in d.get("notes") or ()]
    return lines
