"""A simple well-trajectory text format (for ``--wells FILE``).

Format (one item per line, whitespace-separated, case-insensitive keywords)::

    # comment (also after data: "1 2 3  # note")
    WELL OP_1              # starts a well; the name is the rest of the line
    456000 5930000 1500    # x y z: a trajectory point (z = depth, down positive, as in grids)
    456010 5930005 1650
    MARKER 456012 5930006 1700 top reservoir   # a marker x y z [label]
    WELL WI_1
    ...

A well needs at least one point; markers may come anywhere after its WELL line.  Labels are
accepted and ignored (:class:`~geoshade.models.WellPath` has no field for them); marker cells are
-1 (unknown).  Coordinates are in the grid's coordinate system.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.paths import check_file
from geoshade.models import WellPath


def _numbers(parts, path, lineno, what):
    try:
        vals = [float(v) for v in parts[:3]]
    except ValueError:
        vals = []
    if len(vals) != 3 or not all(np.isfinite(vals)):
        raise InputError(f"{path}:{lineno}: expected {what} as 3 numbers 'x y z', got "
                         f"{' '.join(parts)!r}")
    return vals


def read_wells(path) -> list[WellPath]:
    """Read a well-trajectory file (format in the module text).

    Returns
    -------
    list of WellPath
        In file order; ``markers`` (m, 3) and ``cells`` (m, 3) = -1.

    Raises
    ------
    InputError
        One line with file and line number: points before the first WELL line, a point or
        marker that is not 3 numbers, a well without points, an empty file.

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "wells.txt")
    >>> _ = open(f, "w").write("WELL A\\n0 0 1000\\n0 0 1100  # TD\\nMARKER 0 0 1050 top\\n")
    >>> w = read_wells(f)[0]
    >>> w.name, w.points.shape, w.markers.tolist(), w.cells.tolist()
    ('A', (2, 3), [[0.0, 0.0, 1050.0]], [[-1, -1, -1]])
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{path}: no such file")
    check_file(p, "a well trajectory file")
    wells: list[tuple[str, int, list, list]] = []
    with open(p, encoding="utf-8", errors="replace") as fh:
        for lineno, raw in enumerate(fh, 1):  # lines of a small text file
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            parts = line.split()
            head = parts[0].upper()
            if head == "WELL":
                name = line[len(parts[0]):].strip()
                if not name:
                    raise InputError(f"{path}:{lineno}: WELL needs a name")
                wells.append((name, lineno, [], []))
            elif not wells:
                raise InputError(f"{path}:{lineno}: expected a 'WELL name' line before "
                                 f"{line!r}")
            elif head == "MARKER":
                wells[-1][3].append(_numbers(parts[1:], path, lineno, "MARKER x y z [label]"))
            else:
                if len(parts) != 3:
                    raise InputError(f"{path}:{lineno}: expected a point as 3 numbers 'x y z', "
                                     f"got {line!r}")
                wells[-1][2].append(_numbers(parts, path, lineno, "a point"))
    if not wells:
        raise InputError(f"{path}: no wells; expected 'WELL name' lines followed by 'x y z' rows")
    out = []
    for name, lineno, pts, marks in wells:
        if not pts:
            raise InputError(f"{path}:{lineno}: well {name} has no trajectory points")
        out.append(WellPath(name, np.array(pts), np.array(marks).reshape(-1, 3),
                            np.full((len(marks), 3), -1, np.int64)))
    return out
