"""Public API of the saturation-isosurface view (a thin layer over compute/, io/ and render/)."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from geoshade.compute.grid.geometry import cell_centres
from geoshade.compute.mesh import marching_cubes as mc
from geoshade.errors import InputError
from geoshade.iso.options import DEFAULT_KEYWORD
from geoshade.models.field import FieldSeries, GridSteps
from geoshade.models.grid import CornerPointGrid
from geoshade.models.names import derived_names, grid_property, step_names


class OutsideValuesWarning(UserWarning):
    """Some nodes are NaN or infinite: they are treated as outside the surface."""


def empty_reason(level: float, vmin, vmax) -> str | None:
    """Why no cell can cross ``level`` given the finite value range (None: some may).

    A node is below the level when ``S < S*``; a cell makes triangles when some of its nodes are
    below and some are not, so a surface needs ``vmin < S* <= vmax``.

    >>> empty_reason(2.0, 0.0, 1.0)
    'level 2 is outside the values [0, 1]'
    >>> empty_reason(0.5, 0.0, 1.0) is None
    True
    """
    if vmin is None:
        return "every node is inactive, NaN or infinite"
    s = np.float32(level)
    if s < np.float32(vmin) or s > np.float32(vmax):
        return f"level {level:g} is outside the values [{vmin:g}, {vmax:g}]"
    if s == np.float32(vmin):
        return f"level {level:g} equals the smallest value: no node lies below it"
    return None


def _cell_centres(field: FieldSeries) -> np.ndarray:
    """(nz, ny, nx, 3) float64 cell centres (x, y, depth) of a corner-point field."""

    grid = field.grid
    c = np.asarray(cell_centres(grid), dtype=np.float64)
    nx, ny, nz = grid.dims
    if c.shape == (nx, ny, nz, 3):
        c = c.transpose(2, 1, 0, 3)
    elif c.shape != (nz, ny, nx, 3):
        raise InputError(f"{field.source}: cell centres of shape {c.shape}, expected "
                         f"{(nx, ny, nz, 3)}")
    return c


def geometry(field: FieldSeries, exaggeration: float = 1.0) -> tuple[np.ndarray, np.ndarray | None]:
    """(model matrix 4×4, node positions (nz, ny, nx, 3) float32 or None) of a field.

    Regular grid: positions None (index space), model = :meth:`FieldSeries.index_to_world`.
    Rectilinear grid (the file's own uneven coordinates): positions = the nodes where they are
    (:meth:`FieldSeries.node_positions`) minus the first one, model = translation back.
    Corner-point grid: positions = cell centres minus their minimum (float32 keeps precision
    near the origin), model = translation back and z flipped (depth down -> world z up).
    ``exaggeration`` scales world z (thin reservoirs).

    >>> import numpy as np
    >>> m, pos = geometry(FieldSeries(np.zeros((2, 2, 2)), spacing=(2, 2, 2)))
    >>> pos is None, float(m[0, 0])
    (True, 2.0)
    >>> m, pos = geometry(FieldSeries(np.zeros((3, 2, 2)), coords=([0, 1], [0, 1], [-9, -3, 0])))
    >>> pos[:, 0, 0, 2].tolist(), float(m[2, 3])
    ([0.0, 6.0, 9.0], -9.0)
    """
    if not (np.isfinite(exaggeration) and exaggeration > 0):
        raise InputError(f"exaggeration: expected a positive number, got {exaggeration}")
    exaggerate = np.diag([1.0, 1.0, float(exaggeration), 1.0])
    if field.is_rectilinear:
        nodes = field.node_positions()
        off = nodes[0, 0, 0]
        model = np.eye(4)
        model[:3, 3] = off
        return exaggerate @ model, (nodes - off).astype(np.float32)
    if not field.is_cornerpoint:
        return exaggerate @ field.index_to_world(), None
    c = _cell_centres(field)
    ok = np.isfinite(c).all(axis=-1)
    if not ok.any():
        raise InputError(f"{field.source}: no cell has finite coordinates")
    off = c[ok].min(axis=0)
    local = np.where(ok[..., None], c - off, 0.0).astype(np.float32)
    model = np.diag([1.0, 1.0, -1.0, 1.0])
    model[:3, 3] = off * np.array([1.0, 1.0, -1.0])
    return exaggerate @ model, local


def world_bounds(field: FieldSeries, exaggeration: float = 1.0) -> np.ndarray:
    """(2, 3) box the camera frames: the field's bounds in world coordinates (z up, scaled)."""
    b = field.bounds()
    corners = np.array([[b[i, 0], b[j, 1], b[k, 2]] for i in (0, 1) for j in (0, 1)
                        for k in (0, 1)])
    flip = -1.0 if field.is_cornerpoint else 1.0  # grid bounds are depths
    w = corners * np.array([1.0, 1.0, flip * float(exaggeration)])
    return np.stack([w.min(axis=0), w.max(axis=0)])


@dataclass
class PreparedStep:
    """One step made ready for the GPU (CPU work, done ahead in a thread)."""

    step: int
    values: np.ndarray | None  # (nz, ny, nx) float32, outside at mc.OUTSIDE (None: on the GPU)
    ranges: np.ndarray | None  # patch_ranges(values, L)
    prop: np.ndarray | None    # (nz, ny, nx) float32 colour property
    vmin: float | None
    vmax: float | None
    nonfinite: int
    inactive: int
    prepare_ms: float


def prepare_step(field: FieldSeries, k: int, patch_level: int, color_by=None,
                 slice_axis: str = "z", prepared: mc.PreparedValues | None = None,
                 caps: bool = False, ranges: np.ndarray | None = None) -> PreparedStep:
    """Read step ``k`` and compute what the GPU needs (thread-safe, no GL): the values with
    outside nodes marked and the patch ranges (open surface, or ``caps``; ``ranges``: those
    of ``prepared`` computed already, e.g. by :func:`choose_slice_axis`)."""
    t0 = time.perf_counter()
    pv = prepared if prepared is not None else mc.prepare_values(field.step(k), field.active)
    if ranges is None:
        ranges = mc.patch_ranges(pv.values, patch_level, slice_axis, caps)
    prop = None if color_by is None else prepare_step_property(field, color_by, k)
    return PreparedStep(k, pv.values, ranges, prop, pv.vmin, pv.vmax, pv.nonfinite, pv.inactive,
                        (time.perf_counter() - t0) * 1000)


def prepare_step_property(field: FieldSeries, name: str, k: int) -> np.ndarray:
    """Property ``name`` at step ``k`` as float32, non-finite values set to its finite minimum.

    >>> import numpy as np
    >>> f = FieldSeries(np.zeros((2, 2, 2)), properties={"P": np.array([np.nan, 1, 2, 3] * 2)
    ...                 .reshape(2, 2, 2)})
    >>> prepare_step_property(f, "P", 0).ravel()[:2].tolist()
    [1.0, 1.0]
    """
    prop = field.property_step(name, k)
    bad = ~np.isfinite(prop)
    if bad.any():
        fill = float(prop[~bad].min()) if (~bad).any() else 0.0
        prop = np.where(bad, np.float32(fill), prop).astype(np.float32)
    return prop


def choose_slice_axis(values: mc.PreparedValues, level: float, patch_level: int,
                      slice_axis: str = "auto", caps: bool = False, keep: dict | None = None
                      ) -> str:
    """``slice_axis``, or for "auto" the axis leaving the fewest cells to march (z if empty);
    ``keep`` receives ``{axis: patch ranges}`` of the axis chosen when they were computed.

    >>> import numpy as np
    >>> z, y, x = np.mgrid[0:12, 0:12, 0:12].astype(np.float32)
    >>> choose_slice_axis(mc.prepare_values(y), 5.5, 4)
    'y'
    """
    if slice_axis != "auto":
        if slice_axis not in mc.SLICE_AXES:
            raise InputError(f"slice axis: expected auto, x, y or z, got {slice_axis!r}")
        return slice_axis
    if empty_reason(level, values.vmin, values.vmax) is not None:
        return "z"
    return mc.best_slice_axis(values.values, level, patch_level, caps, keep=keep)[0]


def marchable_refinements(grid: CornerPointGrid, keyword: str) -> list[str]:
    """The refinements of the global grid an isosurface of ``keyword`` is marched over: at
    least 2 cells along every axis (cell centres are the nodes) and the keyword in their
    sections. The others keep their host cells in the global surface."""
    return [r.name for r in grid.refinements
            if not r.parent and min(r.dims) >= 2 and has_quantity(r.grid, keyword)]


def refined_hosts_hidden(field: FieldSeries) -> FieldSeries:
    """``field`` of a grid with local refinements, with the host cells of the refinements
    marched on their own (:func:`marchable_refinements`) inactive: the global surface leaves
    their regions to the refinements' surfaces (:mod:`geoshade.iso.refined`). Any other field
    (or one done already): as it is."""
    grid = field.grid
    if grid is None or not grid.refinements or "hosts_hidden" in grid.meta:
        return field
    keyword = (field.meta or {}).get("keyword") or field.name
    hidden = grid.hosts_hidden(marchable_refinements(grid, keyword))
    active = np.asarray(field.active, bool) & hidden.active.T
    return dataclasses.replace(field, grid=hidden, active=active)


def has_quantity(grid: CornerPointGrid, name: str) -> bool:
    """Whether ``grid`` has quantity ``name`` (any case; a report-step or derived one too)."""
    return str(name).upper() in {n.upper() for n in [*grid.property_names(),
                                                     *derived_names(grid)]}


def field_of(grid: CornerPointGrid, keyword: str | None = None, color_by=None) -> FieldSeries:
    """The :class:`FieldSeries` of one quantity of a corner-point grid (its report steps, or
    its static value as one step), for the isosurface view; report steps stay lazy.

    Every other property of the case comes along as a lazy property to colour the surface by
    (a step is read only when shown): the static ones, and the report-step and derived ones
    (SOIL) when the field has report steps. ``color_by`` names are checked against the case.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> f = field_of(synthetic_grid(4, 3, 2), "poro")
    >>> f.name, f.nsteps, f.shape, sorted(f.properties)
    ('PORO', 1, (2, 3, 4), ['FIPNUM', 'NTG', 'PERMX'])
    >>> sorted(field_of(synthetic_grid(4, 3, 2), "swat").properties)
    ['FIPNUM', 'NTG', 'PERMX', 'PORO', 'SOIL']
    >>> field_of(synthetic_grid(4, 3, 2, steps=0))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: synthetic 4x3x2: no SWAT (the default keyword) and no report steps;
    choose one with --keyword (keyword=): PORO, PERMX, NTG, FIPNUM
    """

    if keyword is None or keyword == "":
        names = [*grid.property_names(), *derived_names(grid)]
        if DEFAULT_KEYWORD not in names:  # a deck, or a case without saturations
            steps = "" if grid.steps else " and no report steps"
            raise InputError(f"{grid.name}: no {DEFAULT_KEYWORD} (the default keyword){steps}; "
                             f"choose one with --keyword (keyword=): "
                             f"{', '.join(names) or 'none'}")
    kw = grid_property(grid, keyword or DEFAULT_KEYWORD)
    assert kw is not None
    dynamic = set(step_names(grid)) | set(derived_names(grid))

    def series(name: str):
        if name in dynamic:
            return GridSteps(grid, name)
        return [np.asarray(grid.properties[name]).T]

    names = [] if color_by is None else ([color_by] if isinstance(color_by, str) else color_by)
    asked = [grid_property(grid, c) for c in names]   # an unknown name is one line here
    # report-step properties come along when the field itself has the report steps
    every = [n for n in [*grid.property_names(), *derived_names(grid)]
             if kw in dynamic or n not in dynamic]
    props = {n: series(n) for n in dict.fromkeys([*every, *asked]) if n is not None and n != kw}
    values = series(kw)
    n = len(values)
    dates = list(grid.step_dates or [])
    times = [d or f"step {k}" for k, d in enumerate(dates)] if kw in dynamic and \
        len(dates) == n else []
    meta = {"format": "grid", "keyword": kw}
    if kw in dynamic and grid.meta.get("unrst_seqnum"):
        meta["reports"] = list(grid.meta["unrst_seqnum"])
    if kw in dynamic and grid.meta.get("default_step") is not None:
        meta["default_step"] = int(grid.meta["default_step"])   # CASE.X0012 opened itself
    return refined_hosts_hidden(FieldSeries(
        values, grid=grid, name=kw, length_unit=grid.units, times=times, properties=props,
        source=grid.name, meta=meta))
