"""Sector models: the cells a filter, a slice and a plane select, written back as a grid.

The rule (the same selection as ``geoshade grid render``): a cell is *selected* when it is
active, inside the slice (an IJK box), passes the filter (evaluated at ``step`` for report-step
keywords, default the last step) and has its centre on the kept side of the plane. The
*sector* is the bounding IJK box of the selected cells: COORD, ZCORN, ACTNUM and every static
property are cut to that box, and the cells in the box that are not selected are made inactive
(ACTNUM 0), so the sector's active cells are exactly the selected ones. Faults keep the faces
inside the box. Report-step keywords are not written (GRDECL and INIT hold static data; the
step only decides the filter).

Written as GRDECL (``.grdecl``, ``.grid``, ``.inc``: every digit, see
:mod:`geoshade.io.grids.grdecl_writer`) or EGRID (``.egrid``) with an INIT beside it (same name,
``.INIT``: PORV and the static properties on the active cells, see
:mod:`geoshade.io.grids.egrid_writer`). PORV = bulk volume × PORO × NTG × MULTPV (those the grid
has; written when it has PORO), the bulk volume integrated exactly over each cell's trilinear
hexahedron in closed form (:func:`cell_volumes`).

>>> import os, tempfile
>>> from geoshade.compute.grid.synthetic import synthetic_grid
>>> g = synthetic_grid(10, 8, 4)
>>> out = export_sector(g, os.path.join(tempfile.mkdtemp(), "S.grdecl"),
...                     filter="PORO > 0.2", slice="i=2:7,k=1:3")
>>> out.cells == out.grid.nactive, out.grid.dims == tuple(s.stop - s.start for s in out.box)
(True, True)
>>> out.box_text()
'I=3-7 J=1-7 K=3-3'
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geoshade.compute.grid.geometry import cell_centres
from geoshade.errors import InputError
from geoshade.grid.options import GridOptions
from geoshade.io import load
from geoshade.io.grids.grdecl_writer import write_grdecl
from geoshade.io.output import Outputs
from geoshade.models import CornerPointGrid, Fault
from geoshade.models.names import properties_at
from geoshade.progress import Counter, Progress

#: output suffixes and their format
FORMATS = {".grdecl": "grdecl", ".grid": "grdecl", ".inc": "grdecl", ".egrid": "egrid"}
_SLAB = 1 << 19


@dataclass
class Sector:
    """What :func:`export_sector` wrote.

    grid:  the sector (a CornerPointGrid of the box; selected cells active)
    box:   (slice i, slice j, slice k) of the box in the source grid (0-based, stop exclusive)
    cells: number of selected cells (= the sector's active cells)
    files: the files written (the grid, and for EGRID its INIT)
    """

    grid: CornerPointGrid
    box: tuple[slice, slice, slice]
    cells: int
    files: list[Path] = field(default_factory=list)

    def box_text(self) -> str:
        """The box as ECLIPSE writes it: 1-based, inclusive (``I=3-7 J=1-8 K=2-3``)."""
        return " ".join(f"{a}={s.start + 1}-{s.stop}" for a, s in zip("IJK", self.box,
                                                                    strict=True))


def _properties_at(grid: CornerPointGrid, k: int | None):

    return properties_at(grid, k)


def selected_cells(grid: CornerPointGrid, filter=None, slice=None, plane=None,
                   step=None) -> np.ndarray:
    """(nx, ny, nz) bool: the active cells inside ``slice``, passing ``filter`` at ``step`` and
    on the kept side of ``plane`` -- what ``geoshade grid render`` shows with those options.

    Parameters
    ----------
    grid : CornerPointGrid
    filter : str, optional
        ``"PORO > 0.2 and PERMX > 100"`` (names in any case; see
        :class:`geoshade.compute.grid.filters.Filter`).
    slice : str or dict, optional
        IJK box ``"i=A:B,j=C:D,k=E"`` (0-based, B exclusive).
    plane : str or Plane, optional
        ``"NX,NY,NZ[,D]"`` in map coordinates, z up (see :class:`geoshade.styles.options.Plane`).
    step : optional
        Report step of the filter's report-step keywords (default: the last).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(6, 5, 3)
    >>> m = selected_cells(g, filter="poro > 0.2", slice="k=1")
    >>> bool((m == (g.active & (g.properties["PORO"] > 0.2)) * (np.arange(3) == 1)).all())
    True
    """
    f = GridOptions.check_filter(filter, grid)
    box = GridOptions.check_slice(slice, grid)
    p = GridOptions.check_plane(plane, grid)
    k = GridOptions.check_step(step, grid)
    mask = grid.active.copy()
    inside = np.zeros(grid.dims, bool)
    inside[box] = True
    mask &= inside
    if f is not None:
        mask &= np.asarray(f.mask(_properties_at(grid, k), grid.dims), bool)
    if p is not None:

        c = np.asarray(cell_centres(grid), np.float64)
        t = grid.map_transform()
        xy = c[..., :2] @ t[:2, :2].T + t[:2, 2]
        world = np.concatenate([xy, -c[..., 2:]], axis=-1)  # z up, as the render's plane
        mask &= p.keeps(world.reshape(-1, 3)).reshape(grid.dims)
    return mask


def bounding_box(mask: np.ndarray) -> tuple[slice, slice, slice]:
    """The smallest IJK box holding every True cell of ``mask`` (InputError when none is).

    >>> m = np.zeros((4, 4, 3), bool); m[1, 2, 0] = m[2, 3, 1] = True
    >>> bounding_box(m)
    (slice(1, 3, None), slice(2, 4, None), slice(0, 2, None))
    """
    if not mask.any():
        raise InputError("sector: no cell is selected (active, inside the slice, passing the "
                         "filter and the plane); nothing to export")
    out = []
    for axis in range(3):
        other = tuple(a for a in range(3) if a != axis)
        hit = np.flatnonzero(mask.any(axis=other))
        out.append(slice(int(hit[0]), int(hit[-1]) + 1))
    return out[0], out[1], out[2]


def _cut_faults(faults, box) -> list[Fault]:
    lo = np.array([s.start for s in box])
    hi = np.array([s.stop for s in box])
    out = []
    for f in faults:
        ijk = f.faces[:, :3]
        keep = np.all((ijk >= lo) & (ijk < hi), axis=1)
        if keep.any():
            faces = f.faces[keep].copy()
            faces[:, :3] -= lo
            out.append(Fault(f.name, faces))
    return out


def cut_sector(grid: CornerPointGrid, mask: np.ndarray) -> tuple[CornerPointGrid, tuple]:
    """The sector of ``grid`` holding the True cells of ``mask`` (see the module's rule), and
    its box.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(6, 5, 3)
    >>> m = np.zeros(g.dims, bool); m[2:4, 1, 1:] = True
    >>> s, box = cut_sector(g, m & g.active)
    >>> s.dims, bool(np.array_equal(s.corners(), g.corners(box)))
    ((2, 1, 2), True)
    """
    mask = np.asarray(mask, bool)
    if mask.shape != grid.dims:
        raise InputError(f"sector: mask shape {mask.shape}, expected the grid's {grid.dims}")
    box = bounding_box(mask)
    bi, bj, bk = box
    # the box is cut before anything is read: a lazy (dask) grid reads only the box
    coord = np.asfortranarray(np.asarray(grid.coord[bi.start:bi.stop + 1,
                                                    bj.start:bj.stop + 1]))
    zcorn = np.asfortranarray(np.asarray(grid.zcorn[2 * bi.start:2 * bi.stop,
                                                    2 * bj.start:2 * bj.stop,
                                                    2 * bk.start:2 * bk.stop]))
    assert grid.actnum is not None  # set by the grid
    act = np.asarray(grid.actnum[box])
    actnum = np.asfortranarray(np.where(mask[box], act, 0).astype(act.dtype))
    props = {name: np.asfortranarray(np.asarray(arr[box])) for name, arr in
             grid.properties.items()}
    label = " ".join(f"{a}={s.start + 1}-{s.stop}" for a, s in zip("IJK", box, strict=True))
    name = f"sector {label} of {grid.name}" if grid.name else f"sector {label}"
    meta = {"format": "sector", "sector_box": [[s.start, s.stop] for s in box],
            "source": grid.name}
    if grid.meta.get("unit_system"):
        meta["unit_system"] = grid.meta["unit_system"]
    return CornerPointGrid(coord, zcorn, actnum=actnum, mapaxes=grid.mapaxes, properties=props,
                           faults=_cut_faults(grid.faults, box), units=grid.units, name=name,
                           meta=meta), box


def _hex_volume(p: np.ndarray) -> np.ndarray:
    """Exact volume of trilinear hexahedra ``p`` ((..., 8, 3), corner a + 2b + 4c): the map
    X(u, v, w) = A + Bu + Cv + Dw + Euv + Fvw + Guw + Huvw integrated in closed form (the
    Jacobian's determinant integrated over the unit cube, a sum of triple products)."""
    p0, p1, p2, p3, p4, p5, p6, p7 = (p[..., c, :] for c in range(8))
    B, C, D = p1 - p0, p2 - p0, p4 - p0
    E, F, G = p3 - p1 - p2 + p0, p6 - p2 - p4 + p0, p5 - p1 - p4 + p0
    H = p7 - p3 - p5 - p6 + p1 + p2 + p4 - p0
    x = np.cross

    def dot(a, b):
        return np.einsum("...i,...i->...", a, b)

    gh = x(G, H)
    v = dot(B, x(C, D + F / 2 + G / 2 + H / 4) - x(D, E / 2 + F / 2 + H / 4)
            + x(E, F / 4 + G / 3 + H / 6) + x(F, G) / 4 - gh / 6)
    v += dot(C, x(D, E / 2 + G / 2 + H / 4) - x(E, F / 3 + G / 4 + H / 6)
             + x(F, G / 4 + H / 6))
    v += dot(D, x(E, F / 4 - G / 4) - x(F, G / 3 + H / 6) + gh / 6)
    v += dot(E, x(F, G / 4 + H / 12) - gh / 12)
    v += dot(F, gh) / 12
    return v


def cell_volumes(grid: CornerPointGrid, progress: Progress | None = None) -> np.ndarray:
    """(nx, ny, nz) float64 bulk volume of every cell: the exact volume of its trilinear
    hexahedron (corners on the pillars, faces bilinear), in closed form. Zero-thickness cells
    have volume 0.

    Examples
    --------
    >>> coord = np.array([[[0, 0, 0, 0, 0, 1], [0, 2, 0, 0, 2, 1]],
    ...                   [[3, 0, 0, 3, 0, 1], [3, 2, 0, 3, 2, 1]]], float)
    >>> zc = np.zeros((2, 2, 2)); zc[..., 1] = 4; zc[1, 1, 1] = 6      # one corner deeper
    >>> float(cell_volumes(CornerPointGrid(coord, zc))[0, 0, 0])        # 3 x 2 x (4 + 2/4)
    27.0
    """

    nx, ny, nz = grid.dims
    out = np.empty((nx, ny, nz), np.float64)
    step = max(1, _SLAB // max(1, nx * ny))
    counter = Counter(progress, nz)
    for k0 in range(0, nz, step):
        k1 = min(nz, k0 + step)
        p = grid.corners((slice(None), slice(None), slice(k0, k1)))   # (nx, ny, nk, 8, 3)
        out[:, :, k0:k1] = np.abs(_hex_volume(p))
        counter.add(k1 - k0)
    return out


def pore_volumes(grid: CornerPointGrid, progress: Progress | None = None) -> np.ndarray | None:
    """(nx, ny, nz) PORV = bulk volume × PORO × NTG × MULTPV (those the grid has), 0 in
    inactive cells; None when the grid has no PORO."""
    have = {str(n).upper(): n for n in grid.properties}
    if "PORO" not in have:
        return None
    porv = cell_volumes(grid, progress)
    for name in ("PORO", "NTG", "MULTPV"):
        if name in have:
            porv *= np.nan_to_num(np.asarray(grid.properties[have[name]], np.float64))
    porv[~grid.active] = 0.0
    return porv


def export_sector(grid, path, filter=None, slice=None, plane=None, step=None,
                  inputs=(), progress: Progress | None = None) -> Sector:
    """Write the sector model of the cells selected by ``filter``, ``slice`` and ``plane``.

    Parameters
    ----------
    grid : CornerPointGrid or path
        The grid (a path is read with :func:`geoshade.io.load`).
    path : str or Path
        ``.grdecl`` / ``.grid`` / ``.inc``: GRDECL; ``.egrid``: EGRID and an INIT beside it
        (same name, ``.INIT``, in the suffix's case).
    filter, slice, plane, step
        The selection, as :func:`selected_cells` (and ``geoshade grid render``) take it.
    inputs : paths
        Files the outputs must not overwrite (the case's files; the grid's own are added).
    progress : callable, optional
        ``progress(done, total)`` while the volumes for PORV are computed.

    Returns
    -------
    Sector

    Raises
    ------
    InputError
        Bad options (one line naming the option), no cell selected, an output suffix geoshade
        does not write, an output that names an input or lies in a missing folder (all
        checked before the work); nothing is left behind by a failed export.
    """

    if isinstance(grid, str | Path):
        grid = load(grid)
    if not isinstance(grid, CornerPointGrid):
        raise InputError(f"sector: expected a CornerPointGrid, got {type(grid).__name__}")
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise InputError(f"{path}: -o: expected a name ending in "
                         f"{', '.join(FORMATS)} (GRDECL or EGRID)")
    outputs = {"-o": path}
    if fmt == "egrid":
        outputs["INIT"] = path.with_suffix(".INIT" if path.suffix.isupper() else ".init")
    own = [grid.meta.get(k) for k in ("source", "init", "unrst_path", "egrid")]
    own += list(grid.meta.get("files") or [])
    with Outputs(outputs, [*inputs, *(f for f in own if f)]) as out:
        mask = selected_cells(grid, filter=filter, slice=slice, plane=plane, step=step)
        sector, box = cut_sector(grid, mask)
        if fmt == "grdecl":
            write_grdecl(sector, out.path("-o"))
        else:
            from geoshade.io.grids.egrid_writer import check_keywords, write_egrid, write_init

            check_keywords(sector, f"{path}: ")
            write_egrid(sector, out.path("-o"))
            write_init(sector, out.path("INIT"), pore_volumes(sector, progress))
        files = out.commit()
    return Sector(sector, box, int(mask.sum()), files)


__all__ = ["FORMATS", "Sector", "bounding_box", "cell_volumes", "cut_sector", "export_sector",
           "pore_volumes", "selected_cells"]
