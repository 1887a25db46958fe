"""Well trajectory files (for ``--wells FILE``): geoshade's own text format, RMS ASCII well
files and CSV, chosen by suffix and content (:func:`read_wells`).

**geoshade wells** (one item per line, whitespace-separated, case-insensitive keywords)::

    # comment (also after data: "1 2 3  # note")
    WELL OP_1              # starts a well; the name is the rest of the line
    456000 5930000 1500    # x y z [md]: a trajectory point (z = depth, down positive, as in
    456010 5930005 1650    # grids; md = measured depth, optional)
    MARKER 456012 5930006 1700 top reservoir   # a marker x y z [label]
    WELL WI_1
    ...

A well needs at least one point; markers may come anywhere after its WELL line.  Labels are
accepted and ignored; marker cells are -1 (unknown).

**RMS ASCII well** (RMS's export, one well per file or several one after another, each with
its own header; suffix ``.rmswell``, ``.rmsw`` or ``.w``,
or found by its header)::

    1.0                        # version
    Unknown                    # well type
    OP_1 456000.0 5930000.0 25 # name, well-head x y, optionally RKB
    2                          # number of logs, then one line per log
    MD  UNK lin
    Zonelog DISC 1 Upper 2 Lower
    456000.0 5930000.0 1500.0 1525.0 1   # x y z (TVD, down positive), then the logs
    ...

-999 marks an undefined value; rows with an undefined x, y or z are left out.  A log called
``MD``, ``M_MDEPTH``, ``MDEPTH`` or ``M_MD`` gives the measured depths; the other logs are read
over and not kept.

**CSV**: rows ``name, x, y, z[, md]`` (commas, semicolons or tabs), the points of a well in
order; a header row is optional and, when present, names the columns (``name``/``well``,
``x``/``east``, ``y``/``north``, ``z``/``tvd``/``depth``, ``md``; any order, other columns
read over).  Wells come in the order of their first row.

Coordinates are in the grid's coordinate system (``--wells-coords map`` for map coordinates).
Every error is one line naming the file and the line.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.paths import check_file
from geoshade.models import WellPath
from geoshade.models.wells import Trajectory

#: suffixes of the formats (anything else is recognised by its content)
RMS_SUFFIXES = (".rmswell", ".rmsw", ".w")
CSV_SUFFIXES = (".csv",)
#: RMS ASCII's undefined value
RMS_UNDEF = -999.0
#: RMS log names that hold measured depth
MD_LOGS = ("MD", "M_MDEPTH", "MDEPTH", "M_MD")
#: CSV header names of each column (lower case)
CSV_COLUMNS = {"name": ("name", "well", "wellname", "well_name"),
               "x": ("x", "east", "easting", "x_utme", "utm_x"),
               "y": ("y", "north", "northing", "y_utmn", "utm_y"),
               "z": ("z", "tvd", "tvdss", "depth", "z_tvdss"),
               "md": ("md", "mdepth", "m_md", "m_mdepth", "measured_depth")}
FORMATS = ("geoshade", "rms", "csv")


def _numbers(parts, path, lineno, what, n=3):
    try:
        vals = [float(v) for v in parts[:n]]
    except ValueError:
        vals = []
    if len(vals) != n or not all(np.isfinite(vals)):
        raise InputError(f"{path}:{lineno}: expected {what}, got {' '.join(parts)!r}")
    return vals


def _lines(p: Path) -> list[str]:
    with open(p, encoding="utf-8", errors="replace") as fh:
        return fh.read().splitlines()


def well_format(path) -> str:
    """``"geoshade"``, ``"rms"`` or ``"csv"``: from the suffix (``.csv``, ``.rmswell`` ...),
    else from the first lines (an RMS header, or a separator in the first line); anything else
    is read as geoshade's format, whose errors name the line.

    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> f = os.path.join(d, "a.txt"); _ = open(f, "w").write("name,x,y,z\\nA,0,0,1\\n")
    >>> well_format(f)
    'csv'
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix in CSV_SUFFIXES:
        return "csv"
    if suffix in RMS_SUFFIXES:
        return "rms"
    head = []
    with open(p, encoding="utf-8", errors="replace") as fh:
        for raw in fh:   # the first few lines only
            line = raw.split("#", 1)[0].strip()
            if line:
                head.append(line)
            if len(head) >= 4:
                break
    if not head or head[0].split()[0].upper() == "WELL":
        return "geoshade"
    if (len(head) >= 4 and re.fullmatch(r"[0-9.]+", head[0])
            and re.fullmatch(r"\d+", head[3])):
        return "rms"
    if re.search(r"[,;\t]", head[0]):
        return "csv"
    return "geoshade"


def read_wells(path) -> list[WellPath]:
    """Read a well-trajectory file in any of the formats of the module text.

    Returns
    -------
    list of WellPath
        In file order; :class:`~geoshade.models.wells.Trajectory` (with ``md``) where the file
        has measured depths or is RMS/CSV; ``markers`` (m, 3) and ``cells`` (m, 3) = -1.

    Raises
    ------
    InputError
        One line with file and line number: points before the first WELL line, a point or
        marker that is not 3 numbers, a well without points, an empty file, a broken RMS
        header, a CSV row with a wrong number of values.

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
    fmt = well_format(p)
    if fmt == "rms":
        return list(read_rms_wells(p))
    if fmt == "csv":
        return read_csv_wells(p)
    return _read_geoshade(p)


def _read_geoshade(path: Path) -> list[WellPath]:
    wells: list[tuple[str, int, list, list]] = []
    for lineno, raw in enumerate(_lines(path), 1):  # lines of a small text file
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
            raise InputError(f"{path}:{lineno}: expected a 'WELL name' line before {line!r}")
        elif head == "MARKER":
            wells[-1][3].append(_numbers(parts[1:], path, lineno,
                                         "MARKER x y z [label] (3 numbers)"))
        else:
            what = "a point as 3 numbers 'x y z' (or 4: 'x y z md')"
            if len(parts) not in (3, 4):
                raise InputError(f"{path}:{lineno}: expected {what}, got {line!r}")
            wells[-1][2].append(_numbers(parts, path, lineno, what, len(parts)))
    if not wells:
        raise InputError(f"{path}: no wells; expected 'WELL name' lines followed by 'x y z' "
                         "rows, an RMS ASCII well file or CSV rows 'name, x, y, z[, md]'")
    out: list[WellPath] = []
    for name, lineno, pts, marks in wells:
        if not pts:
            raise InputError(f"{path}:{lineno}: well {name} has no trajectory points")
        if len({len(q) for q in pts}) > 1:
            raise InputError(f"{path}:{lineno}: well {name} mixes points with and without md; "
                             "give 'x y z md' on every row or on none")
        a = np.array(pts)
        markers = np.array(marks).reshape(-1, 3)
        cells = np.full((len(marks), 3), -1, np.int64)
        out.append(Trajectory(name, a[:, :3], markers, cells, md=a[:, 3]) if a.shape[1] == 4
                   else WellPath(name, a, markers, cells))
    return out


def read_rms_well(path) -> Trajectory:
    """The first well of an RMS ASCII well file (format in the module text;
    :func:`read_rms_wells` reads every well of a file that holds several).

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "OP_1.rmswell")
    >>> _ = open(f, "w").write("1.0\\nUnknown\\nOP 1 100.0 200.0 25\\n2\\nMD UNK lin\\n"
    ...                        "Zone DISC 1 A\\n100 200 1500 1525 1\\n101 200 1600 1626 -999\\n")
    >>> w = read_rms_well(f)
    >>> w.name, w.points[:, 2].tolist(), w.md.tolist()
    ('OP 1', [1500.0, 1600.0], [1525.0, 1626.0])
    """
    return read_rms_wells(path)[0]


def read_rms_wells(path) -> list[Trajectory]:
    """Every well of an RMS ASCII well file: one well, or several one after another (each
    with its own header: version, type, ``name x y [rkb]``, number of logs, log lines, rows).

    A row with one number where a data row has ``3 + logs`` values starts the next well (its
    version line).

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "two.w")
    >>> _ = open(f, "w").write("1.0\\nUnknown\\nA 0 0\\n0\\n0 0 10\\n0 0 20\\n"
    ...                        "1.0\\nUnknown\\nB 5 5 20\\n1\\nMD lin\\n5 5 30 50\\n")
    >>> [(w.name, len(w.points), w.md.tolist()) for w in read_rms_wells(f)]
    [('A', 2, [nan, nan]), ('B', 1, [50.0])]
    """
    lines = _lines(Path(path))
    wells, start = [], 0
    while start < len(lines) and not lines[start].strip():
        start += 1
    while True:
        well, start = _rms_well_at(path, lines, start)
        wells.append(well)
        while start < len(lines) and not lines[start].strip():
            start += 1
        if start >= len(lines):
            return wells


def _rms_well_at(path, lines: list[str], s: int) -> tuple[Trajectory, int]:
    """The well whose header starts at line index ``s``, and the index after its rows."""
    nleft = len(lines) - s
    if nleft < 4:
        what = "the file" if s == 0 else f"the well starting at line {s + 1}"
        raise InputError(f"{path}: an RMS ASCII well needs 4 header lines (version, type, "
                         f"'name x y [rkb]', number of logs); {what} has {nleft} lines")
    row = lines[s + 2].split()
    name = ""
    for n_xy in (3, 2):   # name x y rkb, or name x y (the name may hold spaces)
        try:
            [float(v) for v in row[-n_xy:]]
        except ValueError:
            continue
        if len(row) > n_xy:
            name = " ".join(row[:-n_xy])
            break
    if not name:
        raise InputError(f"{path}:{s + 3}: expected the well header 'name x y [rkb]', got "
                         f"{lines[s + 2].strip()!r}")
    try:
        nlogs = int(lines[s + 3].strip())
    except ValueError:
        nlogs = -1
    if nlogs < 0:
        raise InputError(f"{path}:{s + 4}: expected the number of logs (an integer), got "
                         f"{lines[s + 3].strip()!r}")
    if nleft < 4 + nlogs:
        raise InputError(f"{path}: well {name}: the header announces {nlogs} logs but the file "
                         f"ends after {nleft - 4} log lines")
    logs = [(lines[s + 4 + n].split() or [""])[0] for n in range(nlogs)]
    if not all(logs):
        blank = s + 5 + logs.index("")
        raise InputError(f"{path}:{blank}: expected a log definition 'NAME [TYPE ...]', got an "
                         "empty line")
    first = s + 5 + nlogs   # line number (1-based) of the first data row
    ncol = 3 + nlogs
    rows: list[tuple[int, str]] = []
    end = len(lines)
    for n in range(first, len(lines) + 1):   # rows of one well
        t = lines[n - 1]
        vals = t.split()
        if not vals:
            continue
        if len(vals) == 1 and ncol > 1 and _all_numbers(t) and rows:   # the next well's header
            end = n - 1
            break
        if len(vals) != ncol:
            raise InputError(f"{path}:{n}: expected {ncol} values (x y z and {nlogs} logs), "
                             f"got {len(vals)}: {t.strip()[:60]!r}")
        rows.append((n, t))
    try:
        data = np.array(" ".join(t for _, t in rows).split(), float).reshape(-1, ncol)
    except ValueError:
        bad = next(n for n, t in rows if not _all_numbers(t))
        raise InputError(f"{path}:{bad}: expected numbers, got "
                         f"{lines[bad - 1].strip()[:60]!r}") from None
    data[data == RMS_UNDEF] = np.nan
    keep = np.all(np.isfinite(data[:, :3]), axis=1)
    if not keep.any():
        raise InputError(f"{path}: well {name} has no trajectory point with x, y and z defined "
                         f"({len(data)} rows)")
    md_col = next((3 + n for n, lg in enumerate(logs) if lg.upper() in MD_LOGS), None)
    md = data[keep, md_col] if md_col is not None else None
    return Trajectory(name, data[keep, :3], md=md), end


def _all_numbers(text: str) -> bool:
    try:
        [float(v) for v in text.split()]
    except ValueError:
        return False
    return True


def _csv_columns(header: list[str], path) -> dict[str, int]:
    low = [h.strip().lower() for h in header]
    cols = {}
    for key, names in CSV_COLUMNS.items():
        hit = [n for n, h in enumerate(low) if h in names]
        if hit:
            cols[key] = hit[0]
    missing = [k for k in ("name", "x", "y", "z") if k not in cols]
    if missing:
        raise InputError(f"{path}:1: the header {', '.join(h.strip() for h in header)} has no "
                         f"column for {', '.join(missing)}; expected name, x, y, z[, md]")
    return cols


def read_csv_wells(path) -> list[WellPath]:
    """Wells from CSV rows ``name, x, y, z[, md]`` (format in the module text).

    Examples
    --------
    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "w.csv")
    >>> _ = open(f, "w").write("A,0,0,1000,1000\\nB,5,5,900\\nA,0,1,1100,1101\\n")
    >>> [(w.name, w.points.shape[0], w.md.tolist()) for w in read_csv_wells(f)]
    [('A', 2, [1000.0, 1101.0]), ('B', 1, [nan])]
    """
    text = _lines(Path(path))
    rows = [(n, t) for n, t in enumerate(text, 1) if t.strip() and not t.lstrip().startswith("#")]
    if not rows:
        raise InputError(f"{path}: the file is empty; expected rows 'name, x, y, z[, md]'")
    delim = next((d for d in (",", ";", "\t") if d in rows[0][1]), ",")
    parsed = list(csv.reader((t for _, t in rows), delimiter=delim))
    first = [v.strip() for v in parsed[0]]
    header = not any(_all_numbers(v) and v for v in first[1:])   # no number: names
    if header:
        cols = _csv_columns(first, path)
        parsed, rows = parsed[1:], rows[1:]
    else:
        cols = {"name": 0, "x": 1, "y": 2, "z": 3, "md": 4}
    need = max(cols.values()) + 1 if header else 4
    points: dict[str, list] = {}
    for (lineno, _), vals in zip(rows, parsed, strict=True):   # rows of a small text file
        vals = [v.strip() for v in vals]
        if len(vals) < need or (not header and len(vals) > 5):
            want = f"{need} columns as in the header" if header else "name, x, y, z[, md]"
            raise InputError(f"{path}:{lineno}: expected {want}, got {len(vals)} values")
        name = vals[cols["name"]]
        if not name:
            raise InputError(f"{path}:{lineno}: the well name is empty")
        xyz = _numbers([vals[cols[k]] for k in "xyz"], path, lineno, "numbers x, y, z")
        md_text = vals[cols["md"]] if "md" in cols and cols["md"] < len(vals) else ""
        try:
            md = float(md_text) if md_text else np.nan
        except ValueError:
            raise InputError(f"{path}:{lineno}: expected a number for md, got "
                             f"{md_text!r}") from None
        points.setdefault(name, []).append([*xyz, md])
    if not points:
        raise InputError(f"{path}: no rows after the header; expected 'name, x, y, z[, md]'")
    out: list[WellPath] = []
    for name, pts in points.items():
        a = np.array(pts)
        out.append(Trajectory(name, a[:, :3], md=a[:, 3]))
    return out


__all__ = ["FORMATS", "read_csv_wells", "read_rms_well", "read_rms_wells", "read_wells",
           "well_format"]
