"""Local grid refinements (LGRs, ECLIPSE ``CARFIN``/``REFINE``) of ECLIPSE/OPM output.

Where the files keep them (ECLIPSE File Formats Reference; resdata's ``rd_grid.cpp``; OPM's
``EGrid.cpp`` and ``ERst.cpp``; the layout OPM Flow 2026.4 writes for a ``CARFIN`` case, which
the tests run):

- **EGRID**, after the global grid's ``ENDGRID``, per LGR: ``LGR`` (name), ``LGRPARNT`` (the
  parent LGR, blank for the global grid), ``GRIDHEAD`` (1, NX, NY, NZ, LGR number),
  ``COORD``, ``ZCORN``, ``ACTNUM``, ``HOSTNUM`` (each refined cell's host: a 1-based cell index
  of the parent, i fastest), ``ENDGRID``, ``ENDLGR``.
- **INIT**, after the global arrays, per LGR: ``LGR``, ``LGRHEADI``/``Q``/``D``, the LGR's own
  ``INTEHEAD``/``LOGIHEAD``/``DOUBHEAD`` and its cell arrays (active cells of the LGR), up to the
  next ``LGR``, an ``ENDLGR`` or ``LGRSGONE`` (after the last; global records such as ``TAB``
  may follow it).
- **restart** (unified or not), per report step after the global ``ENDSOL`` (``LGRNAMES``
  inside the global solution lists them): ``LGR`` … ``ENDLGR`` with the LGR's ``INTEHEAD`` and
  ``STARTSOL`` … ``ENDSOL`` arrays (:class:`~geoshade.io.grids.ecl_restart.UnrstIndex`).

The model is :class:`~geoshade.models.grid.Refinement` in ``grid.refinements``: name, parent,
host box, and a :class:`~geoshade.models.CornerPointGrid` of the refined cells with their INIT
properties and report steps.  :func:`describe_refinements` is what ``info`` lists;
:func:`geoshade.io.grids.lgr_interop.refined_to_pyvista` adds the refined cells to a PyVista
conversion.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from geoshade.errors import InputError
from geoshade.io.grids.ecl_records import Record
from geoshade.io.grids.ecl_restart import (
    NOT_CELL,
    CellMap,
    UnrstIndex,
    check_head,
    lazy_steps,
    read_steps,
    restart_bytes,
)
from geoshade.models import CornerPointGrid
from geoshade.models.grid import Refinement

__all__ = ["describe_refinements", "format_refinements", "host_box", "init_sections",
           "lgr_name", "read_refinements", "refinement_init", "refinement_steps"]


def lgr_name(rec: Record) -> str:
    """The name an ``LGR`` or ``LGRPARNT`` record holds, upper case ("" when blank)."""
    v = rec.read("S")
    return bytes(v[0]).decode(errors="replace").strip().upper() if len(v) else ""


def host_box(hostnum: np.ndarray, dims) -> tuple:
    """The 0-based inclusive (i, j, k) box of 0-based host cell indices in a grid of ``dims``.

    Examples
    --------
    >>> host_box(np.array([11, 12, 21, 22]), (10, 10, 3))
    ((1, 2), (1, 2), (0, 0))
    """
    i, j, k = np.unravel_index(np.asarray(hostnum).ravel(), tuple(dims), order="F")
    return tuple((int(a.min()), int(a.max())) for a in (i, j, k))


def read_refinements(path: Path, sections: list[dict[str, Record]], grid: CornerPointGrid,
                     build: Callable[[dict[str, Record], str], CornerPointGrid]
                     ) -> list[Refinement]:
    """The refinements of an EGRID's LGR sections (see the module text), geometry only.

    ``build(records, what)`` makes a section's grid (the EGRID reader's checks, ``what``
    naming the LGR in messages).  A host cell outside its parent, a refined cell without a
    host, or a parent that is not defined before it is one line naming the LGR.
    """
    out: list[Refinement] = []
    grids: dict[str, CornerPointGrid] = {"": grid}
    for sec in sections:
        name = lgr_name(sec["LGR"]) or f"LGR{len(out) + 1}"
        what = f"LGR {name}: "
        parent = lgr_name(sec["LGRPARNT"]) if "LGRPARNT" in sec else ""
        if parent.upper() == "GLOBAL":
            parent = ""
        if parent not in grids:
            raise InputError(f"{path}: {what}LGRPARNT: parent {parent} is not a grid defined "
                             f"before it (known: global{''.join(', ' + g for g in grids if g)})")
        sub = build(sec, what)
        host = grids[parent]
        if "HOSTNUM" not in sec:
            raise InputError(f"{path}: {what}HOSTNUM: not found; expected the host cell of each "
                             f"of its {sub.ncells} cells")
        hn = sec["HOSTNUM"].read("i")
        if hn.size != sub.ncells:
            raise InputError(f"{path}: {what}HOSTNUM: expected {sub.ncells} values (the LGR's "
                             f"cells), got {hn.size}")
        hn = np.asarray(hn, np.int64) - 1
        if hn.size and (int(hn.min()) < 0 or int(hn.max()) >= host.ncells):
            bad = int(hn[(hn < 0) | (hn >= host.ncells)][0]) + 1
            raise InputError(f"{path}: {what}HOSTNUM: host cell {bad} outside the "
                             f"{'×'.join(map(str, host.dims))} parent grid (1..{host.ncells})")
        sub.name = f"{path} (LGR {name})"
        sub.meta.update(lgr=name, parent=parent)
        out.append(Refinement(name, parent, hn.reshape(sub.dims, order="F"),
                              host_box(hn, host.dims), sub))
        grids[name] = sub
    return out


# --- INIT -----------------------------------------------------------------------------------
def init_sections(records: list[Record]) -> tuple[list[Record], dict[str, list[Record]]]:
    """An INIT file's records: (the global grid's, each LGR's by upper-case name)."""
    main: list[Record] = []
    lgrs: dict[str, list[Record]] = {}
    cur: list[Record] | None = None
    for rec in records:
        if rec.keyword == "LGR":
            cur = lgrs.setdefault(lgr_name(rec), [])
        elif rec.keyword in ("ENDLGR", "LGRSGONE"):
            cur = None
        elif cur is not None:
            cur.append(rec)
        else:
            main.append(rec)
    return main, lgrs


def section_properties(path, records: list[Record], grid: CornerPointGrid, what: str = ""
                       ) -> dict[str, dict]:
    """The cell properties of one INIT section on ``grid``'s cells, per medium (``""`` for a
    grid of one medium): INTEHEAD checked against the grid, arrays of its active cells or of
    all cells mapped (NaN / 0 in inactive cells)."""
    heads = [r for r in records if r.keyword == "INTEHEAD"]
    if not heads:
        raise InputError(f"{path}: {what}INTEHEAD: not found; expected an INIT file")
    check_head(f"{path}" + (f" ({what.rstrip(': ')})" if what else ""), heads[0].read("i"),
               grid)
    cm = CellMap(grid)
    out: dict[str, dict] = {m: {} for m in cm.media}
    for rec in records:
        if rec.keyword in NOT_CELL or rec.length not in cm.sizes:
            continue
        if rec.type not in ("REAL", "DOUB", "INTE") or rec.keyword in out[cm.media[0]]:
            continue
        arr = rec.read()
        for m in cm.media:
            cells = cm.cells(arr, m)
            if cells is not None:
                out[m][rec.keyword] = cells
    return out


def refinement_init(path, sections: dict[str, list[Record]], grid: CornerPointGrid) -> None:
    """Put each LGR's INIT properties in its grid (``refinement.grid.properties``); an LGR
    without a section keeps none and says so in its ``meta["notes"]``."""
    for r in grid.refinements:
        recs = sections.get(r.name.upper())
        if recs is None:
            r.grid.meta.setdefault("notes", []).append(f"{Path(path).name} has no section for "
                                                       f"LGR {r.name}: no properties")
            continue
        props = section_properties(path, recs, r.grid, f"LGR {r.name}: ")
        r.grid.properties = props[""]


# --- restart --------------------------------------------------------------------------------
def refinement_steps(grid: CornerPointGrid, index: UnrstIndex, eager_bytes: int) -> None:
    """Each LGR's report steps from the restart's LGR sections (arrays when small, else lazy
    mappings), its dates and report numbers those of the case."""
    for r in grid.refinements:
        view = index.view(lgr=r.name)
        sub = r.grid
        sub.step_dates = list(index.dates)
        sub.meta.update(unrst=view, step_keywords=list(view.keywords),
                        unrst_seqnum=list(index.seqnum))
        if restart_bytes(view) <= eager_bytes:
            sub.steps = read_steps(view, None)
        else:
            sub.steps = list(lazy_steps(view))
        missing = [k for k, o in enumerate(view.offsets) if not o]
        if missing and len(missing) < len(view.offsets):
            sub.meta.setdefault("notes", []).append(
                f"LGR {r.name} has no arrays in report step{'s' if len(missing) > 1 else ''} "
                + ", ".join(map(str, missing[:8])) + (" …" if len(missing) > 8 else ""))


# --- what info says -------------------------------------------------------------------------
def describe_refinements(grid) -> list[dict]:
    """One dict per LGR for ``info``: name, parent ("" global), dims, cells, active cells,
    host box (1-based inclusive ``[[i0, i1], [j0, j1], [k0, k1]]``), host cells, label,
    properties, step keywords.

    Examples
    --------
    >>> from geoshade.models.grid import Refinement
    >>> coord = np.array([[[x, y, 0, x, y, 1] for y in (0, 1)] for x in (0, 1)], float)
    >>> g = CornerPointGrid(coord, np.repeat([[[0.0, 1.0]]], 2, 0).repeat(2, 1))
    >>> d = describe_refinements(CornerPointGrid(g.coord, g.zcorn, refinements=[
    ...     Refinement("L1", "", np.zeros((1, 1, 1)), ((0, 0), (0, 0), (0, 0)), g)]))
    >>> d[0]["label"], d[0]["host_box"]
    ('L1 1×1×1 in I=1 J=1 K=1', [[1, 1], [1, 1], [1, 1]])
    """
    out = []
    for r in getattr(grid, "refinements", None) or []:
        g = r.grid
        out.append({"name": r.name, "parent": r.parent, "dims": list(r.dims),
                    "cells": g.ncells, "active_cells": g.nactive,
                    "host_box": [[lo + 1, hi + 1] for lo, hi in r.host_box],
                    "host_cells": int(np.unique(r.hostnum).size), "label": r.label(),
                    "properties": list(g.properties),
                    "step_keywords": list(g.meta.get("step_keywords") or [])})
    return out


def format_refinements(items: list[dict] | None) -> list[str]:
    """``info``'s lines for :func:`describe_refinements`."""
    if not items:
        return []
    lines = [f"  LGRs     {len(items)} local grid refinement{'s' if len(items) > 1 else ''}"
             " (refined cells inside their host cells)"]
    for d in items:
        what = ", ".join(d["properties"][:6]) + (" …" if len(d["properties"]) > 6 else "")
        lines.append(f"    {d['label']}: {d['cells']:,} cells, {d['active_cells']:,} active, "
                     f"{d['host_cells']:,} host cells"
                     + (f"; properties {what}" if what else "; no properties"))
    return lines
