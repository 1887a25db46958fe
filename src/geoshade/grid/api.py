"""Public API of the reservoir-grid view (a thin layer over compute/ and render/).

Coordinates: the grid's own (x, y, depth) go to the GPU relative to a local origin; the model
matrix applies MAPAXES (grid -> map x, y) and shows depth upwards-negative, scaled by the
vertical exaggeration (world z = -exaggeration * depth: shallow cells on top). Camera framing
depends only on the grid's bounds, so filters, slices, properties and steps never move it.
"""

from __future__ import annotations

import re
import time
import warnings
from collections import ChainMap
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from geoshade.errors import InputError
from geoshade.models.grid import CornerPointGrid, WellPath
from geoshade.styles.image import parse_size

#: the approach ``render`` uses unless told: approach 3 with the faces storage is the one that
#: draws any grid (faults included) with the least GPU memory (``geoshade bench grid``)
DEFAULT_APPROACH = 3
DEFAULT_ZCORN_STORE = "faces"
FAULT_MODES = ("show", "highlight", "hide")
_AXES = "ijk"


class EmptyGridWarning(UserWarning):
    """No cell is drawn (the filter, slice or clip plane removed all of them)."""


class _ComputeFunctions:
    """The compute functions this part relies on, imported when first used."""

    _WHERE: ClassVar[dict[str, str]] = {
        "visible_faces": "geoshade.compute.grid_faces",
        "cell_centres": "geoshade.compute.grid_geometry",
        "zcorn_quantise": "geoshade.compute.grid_geometry",
        "cell_filter": "geoshade.compute.grid_filter",
    }

    def __getattr__(self, name: str):
        import importlib

        if name not in self._WHERE:
            raise AttributeError(name)
        return getattr(importlib.import_module(self._WHERE[name]), name)


def _compute():
    """The ``geoshade.compute.grid_*`` functions (tests may substitute references)."""
    return _ComputeFunctions()


# --- argument parsing ---------------------------------------------------------------------------
def parse_slice(spec, dims) -> tuple[slice, slice, slice]:
    """IJK box from ``"i=A:B,j=C:D,k=E"`` (0-based, B exclusive, as numpy) or a dict.

    >>> parse_slice("i=1:3,k=4", (5, 6, 7))
    (slice(1, 3, None), slice(0, 6, None), slice(4, 5, None))
    >>> parse_slice({"j": (2, None)}, (5, 6, 7))[1]
    slice(2, 6, None)
    """
    out = {ax: (0, n) for ax, n in zip(_AXES, dims, strict=True)}
    if spec is None or spec == "":
        return tuple(slice(*out[ax]) for ax in _AXES)
    expect = ("slice: expected i=A:B,j=A:B,k=A:B with 0-based cell indices (B exclusive, "
              "either side may be left out, a single number is one layer)")
    if isinstance(spec, str):
        items = {}
        for part in spec.split(","):
            m = re.fullmatch(r"\s*([ijkIJK])\s*=\s*(\d*)\s*(?::\s*(\d*))?\s*", part)
            if not m:
                raise InputError(f"{expect}; got {spec!r}")
            ax, a, b = m.group(1).lower(), m.group(2), m.group(3)
            if ax in items:
                raise InputError(f"slice: axis {ax} given twice in {spec!r}")
            if b is None:  # a single layer
                if a == "":
                    raise InputError(f"{expect}; got {spec!r}")
                items[ax] = (int(a), int(a) + 1)
            else:
                items[ax] = (int(a) if a else None, int(b) if b else None)
    elif isinstance(spec, dict):
        items = {}
        for ax, v in spec.items():
            if str(ax).lower() not in _AXES:
                raise InputError(f"slice: unknown axis {ax!r}; expected i, j or k")
            if isinstance(v, slice):
                v = (v.start, v.stop)
            elif np.isscalar(v):
                v = (int(v), int(v) + 1)
            items[str(ax).lower()] = tuple(v)
    else:
        raise InputError(f"{expect}; got {spec!r}")
    for ax, (a, b) in items.items():
        n = dims[_AXES.index(ax)]
        a = 0 if a is None else int(a)
        b = n if b is None else int(b)
        if not 0 <= a < b <= n:
            raise InputError(f"slice: {ax}={a}:{b} is empty or outside 0:{n} (the grid has "
                             f"{n} cells along {ax})")
        out[ax] = (a, b)
    return tuple(slice(*out[ax]) for ax in _AXES)


def parse_clip(plane) -> np.ndarray | None:
    """``"NX,NY,NZ,D"`` or 4 numbers -> (4,) float.

    Cells are kept where ``n̂·(c - centre) + D >= 0``: ``c`` the cell centre and ``centre`` the
    grid's centre in map x, y and depth (positive down), ``n̂`` the unit normal, so the plane
    lies D metres from the grid's centre and the kept side is the one ``n`` points to.

    >>> parse_clip("1,0,0,-5").tolist()
    [1.0, 0.0, 0.0, -5.0]
    """
    if plane is None:
        return None
    try:
        vals = ([float(v) for v in plane.split(",")] if isinstance(plane, str)
                else [float(v) for v in plane])
    except (TypeError, ValueError):
        raise InputError(f"clip: expected NX,NY,NZ,D (four numbers), got {plane!r}") from None
    if len(vals) != 4 or not np.all(np.isfinite(vals)) or not any(vals[:3]):
        raise InputError(f"clip: expected NX,NY,NZ,D with a non-zero normal, got {plane!r}")
    return np.array(vals)


def display_bounds(grid: CornerPointGrid) -> np.ndarray:
    """(2, 3) grid-coordinate bounds (x, y, depth) of the pillars and the active cells' depths."""
    b = grid.bounds()
    act = grid.active
    if act.any():
        z = np.asarray(grid.zcorn).reshape(2, grid.dims[0], 2, grid.dims[1], 2, grid.dims[2],
                                           order="F")
        za = z.transpose(1, 3, 5, 0, 2, 4)[act]
        b[0, 2], b[1, 2] = float(za.min()), float(za.max())
    return b


def model_matrix(grid: CornerPointGrid, origin, exaggeration: float = 1.0) -> np.ndarray:
    """4×4 matrix from local GPU coordinates (x, y, depth minus ``origin``) to the world.

    World x, y are map coordinates (MAPAXES applied); world z = -exaggeration * depth.
    """
    t = grid.map_transform()
    o = np.asarray(origin, float)
    m = np.eye(4)
    m[:2, :2] = t[:2, :2]
    m[:2, 3] = t[:2, :2] @ o[:2] + t[:2, 2]
    m[2, 2] = -float(exaggeration)
    m[2, 3] = -float(exaggeration) * o[2]
    return m


def world_points(grid: CornerPointGrid, pts, exaggeration: float, coords: str = "grid"
                 ) -> np.ndarray:
    """(n, 3) grid (or map) x, y, depth -> world x, y, z (float64)."""
    p = np.asarray(pts, float).reshape(-1, 3)
    out = np.empty_like(p)
    if coords == "grid":
        t = grid.map_transform()
        out[:, :2] = p[:, :2] @ t[:2, :2].T + t[:2, 2]
    elif coords == "map":
        out[:, :2] = p[:, :2]
    else:
        raise InputError(f"wells_coords: expected 'grid' or 'map', got {coords!r}")
    out[:, 2] = -float(exaggeration) * p[:, 2]
    return out


def world_bounds(grid: CornerPointGrid, exaggeration: float = 1.0) -> np.ndarray:
    b = display_bounds(grid)
    corners = np.array([[b[i, 0], b[j, 1], b[k, 2]] for i in (0, 1) for j in (0, 1)
                        for k in (0, 1)])
    w = world_points(grid, corners, exaggeration)
    return np.array([w.min(0), w.max(0)])


def frame_points(grid: CornerPointGrid, exaggeration: float = 1.0) -> np.ndarray:
    """(8, 3) world points the view must show: the grid's four corner pillars at the top and
    bottom depths of its active cells."""
    nx, ny, _ = grid.dims
    b = display_bounds(grid)
    c = np.asarray(grid.coord, float)[[0, nx, 0, nx], [0, 0, ny, ny]]  # (4, 6)
    pts = []
    for z in (b[0, 2], b[1, 2]):
        dz = c[:, 5] - c[:, 2]
        t = np.where(dz != 0, (z - c[:, 2]) / np.where(dz != 0, dz, 1.0), 0.0)
        pts.append(np.stack([c[:, 0] + t * (c[:, 3] - c[:, 0]),
                             c[:, 1] + t * (c[:, 4] - c[:, 1]), np.full(4, z)], axis=1))
    return world_points(grid, np.concatenate(pts), exaggeration)


# --- the view --------------------------------------------------------------------------------
@dataclass
class _State:
    property: str | None = None
    step: int | None = None
    filter: str | None = None
    slice: object = None
    clip: np.ndarray | None = None
    faults: str = "show"
    exaggeration: float = 1.0
    color_range: tuple | None = None
    notes: list = field(default_factory=list)


@dataclass
class PreparedFaces:
    """Visible faces built on the CPU for a filter/slice/clip/faults change (see
    :meth:`GridView.prepare_faces`), ready for :meth:`GridView.apply_faces`."""

    changes: dict
    mask: np.ndarray
    faces: object
    cells: np.ndarray
    face: np.ndarray
    highlight: np.ndarray | None
    ms: float


class GridView:
    """A live view of one corner-point grid; only what changed is redone.

    - :meth:`set_property` / :meth:`set_step`: new per-cell colour indices, written into the
      existing colour object (the geometry is not touched);
    - :meth:`set_filter` / :meth:`set_slice` / :meth:`set_clip` / :meth:`set_faults`: new
      visible faces from the grid in memory (nothing is read again), uploaded as face data;
    - :meth:`set_exaggeration` and a new camera: just draw again.

    Examples
    --------
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> view = GridView(synthetic_grid(8, 6, 4), property="PORO", size=(64, 48))
    >>> geometry = view.visual.cache.get("coord")
    >>> view.set_property("PERMX")                  # colour data only
    >>> view.visual.cache.get("coord") is geometry
    True
    >>> img, stats = view.draw()
    >>> view.release()
    >>> stats["property"], img.shape
    ('PERMX', (48, 64, 4))
    """

    def __init__(self, grid: CornerPointGrid, property=None, step=None, filter=None,
                 slice=None, clip_plane=None, faults: str = "show", exaggeration: float = 1.0,
                 approach: int = DEFAULT_APPROACH, zcorn_bits: int = 16,
                 zcorn_store: str = DEFAULT_ZCORN_STORE, edges=False, edge_style=None,
                 cull: bool = True, colormap: str = "viridis", color_range=None, palette=None,
                 wells=None, wells_coords: str = "grid", well_radius=None,
                 size=(1024, 768), smear_faults: bool = False, ctx=None):
        from geoshade.render.context import get_context
        from geoshade.render.visuals.grid.visual import EdgeStyle, GridVisual
        from geoshade.styles.palette import palette as make_palette
        from geoshade.styles.shading import shading_uniforms

        if not isinstance(grid, CornerPointGrid):
            raise InputError(f"grid: expected a CornerPointGrid, got {type(grid).__name__}")
        self.grid = grid
        self.ctx = ctx if ctx is not None else get_context()
        self.size = parse_size(size)
        self.cull = bool(cull)
        try:
            approach = int(approach)
        except (TypeError, ValueError):
            raise InputError(f"approach: expected 1, 2 or 3, got {approach!r}") from None
        self.edge_style = edge_style if edge_style is not None else EdgeStyle()
        self.set_edges(edges)
        self.palette = (np.asarray(palette, np.uint8) if palette is not None
                        else make_palette(colormap))
        if self.palette.shape != (256, 4):
            raise InputError(f"palette: expected (256, 4) uint8 RGBA, got {self.palette.shape}")
        self.shading = shading_uniforms()
        self.fn = _compute()
        self.state = _State(exaggeration=_check_exaggeration(exaggeration))
        b = display_bounds(grid)
        self.origin = b.mean(axis=0)
        t0 = time.perf_counter()
        quantised = None
        if approach != 1 and zcorn_bits == 16:
            quantised = self.fn.zcorn_quantise(np.asarray(grid.zcorn), bits=16)
        self.visual = GridVisual(self.ctx, grid, self.origin, approach=approach,
                                 zcorn_bits=zcorn_bits, zcorn_store=zcorn_store,
                                 quantised=quantised, palette=self.palette,
                                 smear_faults=smear_faults)
        self.geometry_ms = (time.perf_counter() - t0) * 1000
        self.wells_visual = None
        self.target = None
        self._centres = None
        self._mask = None
        self.faces = None
        self.colors_ms = self.faces_ms = 0.0
        self.set_property(property, step=step, color_range=color_range, _upload=False)
        self.state.filter, self.state.slice = filter, parse_slice(slice, grid.dims)
        self.state.clip = parse_clip(clip_plane)
        if faults not in FAULT_MODES:
            raise InputError(f"faults: expected one of {', '.join(FAULT_MODES)}, got {faults!r}")
        self.state.faults = faults
        self._update_faces()
        self._upload_colors()
        if wells:
            self.set_wells(wells, coords=wells_coords, radius=well_radius)

    # --- colours -------------------------------------------------------------------------------
    def property_names(self) -> list[str]:
        return self.grid.property_names()

    def _values(self, name: str, step):
        g = self.grid
        nsteps = len(g.steps)
        if step is not None:
            try:
                step = int(step)
            except (TypeError, ValueError):
                raise InputError(f"step: expected an integer, got {step!r}") from None
            if nsteps == 0:
                raise InputError(f"step: {g.name or 'the grid'} has no report steps (no "
                                 f"UNRST); step {step} does not exist")
            if not 0 <= step < nsteps:
                raise InputError(f"step: {step} does not exist; {g.name or 'the grid'} has "
                                 f"{nsteps} report steps (0..{nsteps - 1})")
        if name is None:
            return None, step
        dynamic = [n for n in (g.steps[0] if nsteps else {})]
        if name in g.properties and (step is None or name not in dynamic):
            return np.asarray(g.properties[name]), step
        if name in dynamic:
            if step is None:
                step = 0
                self.state.notes.append(f"{name} is a report-step property: step 0 shown")
            return np.asarray(g.steps[step][name]), step
        names = g.property_names()
        raise InputError(f"property: unknown name {name!r}; {g.name or 'the grid'} has "
                         f"{', '.join(names) if names else 'no properties'}")

    def set_property(self, name=None, step=None, color_range=None, _upload=True) -> None:
        """Colour the cells by ``name`` (at report ``step``): uploads colour data only."""
        from geoshade.render.visuals.grid.prepare import color_index

        values, step = self._values(name, step)
        st = self.state
        old_step = st.step
        t0 = time.perf_counter()
        if values is None:
            crange, ci = None, np.full(self.grid.ncells, 160, np.uint8)
        else:
            v = np.asarray(values, np.float64).ravel(order="F")
            if color_range is not None:
                try:
                    lo, hi = (float(x) for x in color_range)
                except (TypeError, ValueError):
                    lo = hi = float("nan")
                if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
                    raise InputError(f"range: expected LO <= HI (finite), got {color_range!r}")
            else:
                act = v[self.grid.active.ravel(order="F") & np.isfinite(v)]
                lo, hi = (float(act.min()), float(act.max())) if act.size else (0.0, 1.0)
            crange, ci = (lo, hi), color_index(v, lo, hi)
        st.property, st.step, st.color_range, self._ci = name, step, crange, ci
        self.colors_ms = (time.perf_counter() - t0) * 1000
        if _upload:
            refilter = old_step != st.step and self._filter_uses_steps()
            self._upload_colors()
            if refilter:
                self._update_faces()

    def set_colormap(self, name: str = "viridis", palette=None) -> None:
        """A new palette (a matplotlib colour map or a (256, 4) uint8 array): 1 KB upload."""
        from geoshade.styles.palette import palette as make_palette

        pal = np.asarray(palette if palette is not None else make_palette(name), np.uint8)
        if pal.shape != (256, 4):
            raise InputError(f"palette: expected (256, 4) uint8 RGBA, got {pal.shape}")
        self.palette = pal
        self.visual.set_palette(pal)

    def set_step(self, step) -> None:
        """Show report ``step`` of the current property (colour data only, unless the filter
        uses report-step properties)."""
        self.set_property(self.state.property, step=step, color_range=None)

    def _upload_colors(self) -> None:
        t0 = time.perf_counter()
        self.visual.set_colors(self._ci)
        self.ctx.finish()
        self.colors_ms += (time.perf_counter() - t0) * 1000

    # --- what is drawn ---------------------------------------------------------------------------
    def _change(self, **values) -> None:
        """Set state fields and redo the faces; on an error the view stays as it was."""
        self.apply_faces(self.prepare_faces(**values))

    def set_filter(self, expr) -> None:
        """Show only the cells where ``expr`` holds (e.g. ``"PORO > 0.2 and PERMX > 100"``)."""
        self._change(filter=expr or None)

    def set_slice(self, spec) -> None:
        """IJK box (see :func:`parse_slice`); ``None`` for the whole grid."""
        self._change(slice=parse_slice(spec, self.grid.dims))

    def set_clip(self, plane) -> None:
        """Clipping plane (see :func:`parse_clip`); ``None`` for none."""
        self._change(clip=parse_clip(plane))

    def set_faults(self, mode: str) -> None:
        """``'show'``, ``'highlight'`` or ``'hide'`` the fault faces."""
        if mode not in FAULT_MODES:
            raise InputError(f"faults: expected one of {', '.join(FAULT_MODES)}, got {mode!r}")
        self._change(faults=mode)

    def set_exaggeration(self, factor: float) -> None:
        self.state.exaggeration = _check_exaggeration(factor)
        if self.wells_visual is not None:
            self.set_wells(self._wells, self._wells_coords, self._well_radius)

    def set_edges(self, edges) -> None:
        """``False``/``'none'``, ``True``/``'quad'`` or ``'paper'``."""
        mode = {False: "none", None: "none", True: "quad"}.get(edges, edges)
        if mode not in ("none", "quad", "paper"):
            raise InputError(f"edges: expected none, quad or paper, got {edges!r}")
        self.edge_style.mode = mode

    def filter_properties(self, state=None):
        """Static properties and those of the current report step, read only when the filter
        names them (report steps may be lazy mappings over the UNRST file)."""
        g = self.grid
        if not g.steps:
            return g.properties
        return ChainMap(g.steps[(state or self.state).step or 0], g.properties)

    def _filter_uses_steps(self) -> bool:
        g, expr = self.grid, self.state.filter
        if not expr or not g.steps:
            return False
        words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", expr))
        return any(name in words for name in g.steps[0])

    def shown_mask(self, state=None) -> np.ndarray:
        """(nx, ny, nz) bool: active cells inside the slice, passing the filter and the clip
        plane (see :func:`parse_clip`) of ``state`` (default: the current one)."""
        g, st = self.grid, state or self.state
        mask = g.active.copy()
        box = np.zeros(g.dims, bool)
        box[st.slice] = True
        mask &= box
        if st.filter:
            fm = np.asarray(self.fn.cell_filter(st.filter, self.filter_properties(st), g.dims),
                            bool)
            mask &= fm.reshape(g.dims)
        if st.clip is not None:
            if self._centres is None:
                c = np.asarray(self.fn.cell_centres(g), np.float64).reshape(*g.dims, 3)
                t = g.map_transform()
                xy = c[..., :2] @ t[:2, :2].T + t[:2, 2]
                self._centres = np.concatenate([xy, c[..., 2:]], axis=-1)
            n = st.clip[:3] / np.linalg.norm(st.clip[:3])
            centre = display_bounds(g).mean(axis=0)
            centre[:2] = centre[:2] @ g.map_transform()[:2, :2].T + g.map_transform()[:2, 2]
            mask &= (self._centres - centre) @ n + st.clip[3] >= 0
        return mask

    def prepare_faces(self, **changes) -> PreparedFaces:
        """CPU half of a change of ``filter``, ``slice``, ``clip`` or ``faults``: the cells shown
        and their visible faces, from the grid in memory. No GL: safe on a worker thread (a
        viewer keeps its window alive this way); errors leave the view as it was."""
        t0 = time.perf_counter()
        state = replace(self.state, **changes)
        mask = self.shown_mask(state)
        fs = self.fn.visible_faces(self.grid, shown=mask)
        cells, face = np.asarray(fs.cells), np.asarray(fs.face)
        fault = np.asarray(fs.fault, bool)
        named = np.asarray(getattr(fs, "fault_id", np.full(face.size, -1))) >= 0
        keep = np.ones(face.size, bool)
        hl = None
        if state.faults == "hide":
            keep = ~(fault & np.asarray(fs.neighbour_shown, bool))
        elif state.faults == "highlight":
            hl = (fault | named)[keep]
        return PreparedFaces(changes, mask, fs, cells[keep], face[keep], hl,
                             (time.perf_counter() - t0) * 1000)

    def apply_faces(self, prepared: PreparedFaces) -> None:
        """GL half: upload the faces of :meth:`prepare_faces` and make its state current."""
        t0 = time.perf_counter()
        self.visual.set_faces(prepared.cells, prepared.face, prepared.highlight)
        self.ctx.finish()
        for k, v in prepared.changes.items():
            setattr(self.state, k, v)
        self._mask, self.faces = prepared.mask, prepared.faces
        self.n_faceset = int(np.asarray(prepared.faces.face).size)
        self.faces_ms = prepared.ms + (time.perf_counter() - t0) * 1000

    def _update_faces(self) -> None:
        self.apply_faces(self.prepare_faces())

    # --- wells ---------------------------------------------------------------------------------
    def set_wells(self, wells, coords: str = "grid", radius=None) -> None:
        """Draw ``wells`` (WellPath list) as impostor tubes, their markers as spheres."""
        from geoshade.render.visuals.wells.visual import WellsVisual

        wells = list(wells or [])
        for w in wells:
            if not isinstance(w, WellPath):
                raise InputError(f"wells: expected WellPath objects, got {type(w).__name__}")
        self._wells, self._wells_coords, self._well_radius = wells, coords, radius
        if self.wells_visual is not None:
            self.wells_visual.release()
            self.wells_visual = None
        if not wells:
            return
        exag = self.state.exaggeration
        wb = world_bounds(self.grid, exag)
        r = float(radius) if radius is not None else 0.004 * float(np.linalg.norm(wb[1] - wb[0]))
        self._wells_origin = wb.mean(axis=0)
        paths = [world_points(self.grid, w.points, exag, coords) - self._wells_origin
                 for w in wells]
        markers = [world_points(self.grid, w.markers, exag, coords) - self._wells_origin
                   for w in wells if len(w.markers)]
        self.wells_visual = WellsVisual(self.ctx, paths, markers, radius=r)

    # --- drawing -----------------------------------------------------------------------------
    def camera(self, view="iso", azimuth=None, elevation=None, zoom=1.0, ortho=False):
        """The camera framed on the whole grid (independent of filters and slices)."""
        from geoshade.render.visuals.grid.framing import framed_camera

        w, h = self.size
        exag = self.state.exaggeration
        return framed_camera(world_bounds(self.grid, exag), view=view, azimuth=azimuth,
                             elevation=elevation, zoom=zoom, ortho=ortho, aspect=w / h,
                             points=frame_points(self.grid, exag))

    def draw(self, camera=None, transparent: bool = False, background=(1.0, 1.0, 1.0),
             frames: int = 1, count: bool = True) -> tuple[np.ndarray, dict]:
        """Render; returns the RGBA image ``(h, w, 4) uint8`` and the stats dict."""
        from geoshade.render.target import Offscreen, time_frames

        if self.target is None or self.target.size != self.size:
            if self.target is not None:
                self.target.release()
            self.target = Offscreen(self.ctx, self.size)
        target = self.target
        cam = (camera if camera is not None else self.camera()).with_aspect(target.aspect)
        model = model_matrix(self.grid, self.origin, self.state.exaggeration)
        bg = (*background[:3], 0.0 if transparent else 1.0)
        vis = self.visual

        def frame(count_now=False):
            target.clear(bg)
            # the counting frame draws every face (no back-face cull: the same picture), so
            # faces_drawn is the number of faces the GPU built, equal to the FaceSet's
            out = vis.draw(cam, model, self.shading, target.size, self.edge_style,
                           cull=self.cull and not count_now, count=count_now)
            if self.wells_visual is not None:
                wm = np.eye(4)
                wm[:3, 3] = self._wells_origin
                self.wells_visual.draw(cam, wm, self.shading)
            return out

        first_ms, median_ms = time_frames(self.ctx, frame, frames=max(1, frames))
        counts = frame(True) if count else {}
        img = target.read()
        stats = self._stats(target, first_ms, median_ms, counts)
        if stats["faces"] == 0:
            msg = "empty view: no cell passes the filter, slice and clip plane"
            stats["warning"] = msg
            warnings.warn(msg, EmptyGridWarning, stacklevel=2)
        return img, stats

    def _stats(self, target, first_ms, median_ms, counts) -> dict:
        g, st, vis = self.grid, self.state, self.visual
        gpu = vis.gpu_bytes + (self.wells_visual.gpu_bytes if self.wells_visual else 0)
        store = f" ({vis.zcorn_store})" if vis.approach == 3 else ""
        s = {
            "width": target.size[0], "height": target.size[1],
            "method": f"approach {vis.approach}{store}",
            "frame_ms": round(median_ms, 3), "first_frame_ms": round(first_ms, 3),
            "gpu_bytes": int(gpu), "cells": int(g.ncells), "active_cells": int(g.nactive),
            "shown_cells": int(np.count_nonzero(self._mask)),
            "faces": int(vis.n_faces), "faceset_faces": self.n_faceset,
            "faces_drawn": counts.get("faces_drawn"), "triangles": counts.get("triangles"),
            "approach": vis.approach, "zcorn_store": vis.zcorn_store,
            "zcorn_bits": vis.zcorn_bits, "zcorn_max_error": vis.zcorn_max_error,
            "property": st.property, "step": st.step,
            "range": list(st.color_range) if st.color_range else None,
            "filter": st.filter, "faults": st.faults, "edges": self.edge_style.mode,
            "cull": self.cull, "exaggeration": st.exaggeration,
            "gpu_breakdown": vis.cache.breakdown(),
            "geometry_ms": round(self.geometry_ms, 3), "faces_ms": round(self.faces_ms, 3),
            "colors_ms": round(self.colors_ms, 3),
            "renderer": self.ctx.info.get("GL_RENDERER"),
        }
        if vis.approach == 1:
            s["node_spread"] = vis.node_spread
        if self.wells_visual is not None:
            s["wells"] = self.wells_visual.n_wells
            s["well_segments"] = self.wells_visual.n_segments
        if st.notes:
            s["notes"] = list(dict.fromkeys(st.notes))
        return s

    def release(self) -> None:
        for obj in (self.visual, self.wells_visual, self.target):
            if obj is not None:
                obj.release()
        self.visual = self.wells_visual = self.target = None


def _check_exaggeration(f) -> float:
    try:
        f = float(f)
    except (TypeError, ValueError):
        raise InputError(f"exaggeration: expected a positive number, got {f!r}") from None
    if not (np.isfinite(f) and f > 0):
        raise InputError(f"exaggeration: expected a positive number, got {f}")
    return f


def render(grid: CornerPointGrid, property=None, step=None, filter=None, slice=None,
           edges=False, approach: int = DEFAULT_APPROACH, wells=None, clip_plane=None,
           faults: str = "show", exaggeration: float = 1.0, camera=None, view: str = "iso",
           azimuth=None, elevation=None, zoom: float = 1.0, ortho: bool = False,
           size=(1024, 768), transparent: bool = False, colormap: str = "viridis",
           color_range=None, zcorn_bits: int = 16, zcorn_store: str = DEFAULT_ZCORN_STORE,
           cull: bool = True, wells_coords: str = "grid", well_radius=None,
           smear_faults: bool = False, frames: int = 5, count: bool = True, palette=None,
           ctx=None) -> tuple[np.ndarray, dict]:
    """Render a corner-point grid coloured by a cell property.

    Parameters
    ----------
    grid : CornerPointGrid
    property : str, optional
        Cell property (static, or of the report step ``step``); default a uniform colour.
    step : int, optional
        Report step (0-based) for report-step properties (``grid.steps``).
    filter : str, optional
        Cell filter such as ``"PORO > 0.2 and PERMX > 100"``.
    slice : str or dict, optional
        IJK box ``"i=A:B,j=C:D,k=E"`` (0-based, B exclusive).
    edges : bool or {'quad', 'paper'}
        Cell edges drawn in the same pass (``True`` = ``'quad'``).
    approach : {1, 2, 3}
        The paper's approaches (1 needs a conforming grid).
    wells : list of WellPath, optional
        Trajectories (tubes) and markers (spheres), in grid coordinates unless
        ``wells_coords='map'``.
    clip_plane : (nx, ny, nz, d), optional
        Keep the cells whose centre ``c`` (map x, y, depth) has ``n̂·(c - centre) + d >= 0``,
        ``centre`` the grid's centre and ``n̂`` the unit normal (d in metres).
    faults : {'show', 'highlight', 'hide'}
    exaggeration : float
        Vertical exaggeration (depth scale).

    Returns
    -------
    image : (h, w, 4) uint8
    stats : dict
        ``width height method frame_ms gpu_bytes cells active_cells faces_drawn approach
        zcorn_bits zcorn_max_error property step`` and more.

    Examples
    --------
    >>> from geoshade.compute.synthetic_grid import synthetic_grid
    >>> from geoshade.grid import render
    >>> img, stats = render(synthetic_grid(8, 6, 4), property="PORO", edges=True,
    ...                     size=(64, 48), frames=1)
    >>> img.shape, stats["faces_drawn"] == stats["faces"], stats["approach"]
    ((48, 64, 4), True, 3)
    """
    view_ = GridView(grid, property=property, step=step, filter=filter, slice=slice,
                     clip_plane=clip_plane, faults=faults, exaggeration=exaggeration,
                     approach=approach, zcorn_bits=zcorn_bits, zcorn_store=zcorn_store,
                     edges=edges, cull=cull, colormap=colormap, color_range=color_range,
                     palette=palette, wells=wells, wells_coords=wells_coords,
                     well_radius=well_radius, size=size, smear_faults=smear_faults, ctx=ctx)
    try:
        cam = camera or view_.camera(view=view, azimuth=azimuth, elevation=elevation,
                                     zoom=zoom, ortho=ortho)
        return view_.draw(cam, transparent=transparent, frames=frames, count=count)
    finally:
        view_.release()
