"""geoshade models ⇄ PyVista datasets (the optional ``pyvista`` extra).

=====================  ==================================  =======================================
geoshade model         PyVista dataset                     what carries what
=====================  ==================================  =======================================
``VoxelVolume``        ``ImageData``                       voxels are *cells*: ``dimensions`` =
                                                           voxels + 1, ``origin`` = the volume's
                                                           (corner of voxel 0), ``spacing``; the
                                                           values as one cell array (x fastest,
                                                           no copy); the selection ``lo, hi`` as
                                                           an optional uint8 cell array
                                                           ``selected``
``CornerPointGrid``    ``ExplicitStructuredGrid``          one hexahedron per cell (i fastest,
                                                           then j, k), its 8 corners on the
                                                           pillars (COORD) at the ZCORN depths;
                                                           inactive cells (ACTNUM 0) *hidden*
                                                           (``vtkGhostType`` HIDDENCELL); static
                                                           properties and the chosen report
                                                           step's keywords as cell arrays under
                                                           their geoshade names
``FieldSeries``        ``ImageData`` (regular: node        a field's nodes are *points* (regular
                       values as point data) or the        grids) or cells (corner-point grids);
                       grid's ``ExplicitStructuredGrid``   one array per step
``TriangleMesh``       ``PolyData``                        vertices, triangles, ``Normals`` and
                                                           the values as point arrays
``StackModel``         ``UnstructuredGrid``                one hexahedron per non-empty interval,
                                                           exact for intervals of any height
                                                           (an ``ImageData`` is exact only when
                                                           every interval starts on a level);
                                                           cell arrays ``code``, ``column``,
                                                           ``log``
=====================  ==================================  =======================================

Coordinates stay the model's: a corner-point grid keeps its grid coordinates (before MAPAXES)
with z the depth, down positive, as in its files (``z_up=True`` negates z so that PyVista shows
it the right way up; the hexahedra are then mirrored, which VTK's cell-quality filters report as
negative volumes). What a dataset cannot say itself (the geoshade model, units, names, the
grid's COORD, the stacks' legend) goes into ``field_data`` under ``geoshade*`` names, so that
:func:`from_pyvista` gives the model back unchanged. Datasets made elsewhere convert too where
the inverse is defined: an ``ImageData`` (cell data: voxels; point data: voxels centred on the
points), an ``ExplicitStructuredGrid`` whose corner points lie on pillars (a corner-point
layout), a ``PolyData`` of triangles.

Examples
--------
>>> import numpy as np, geoshade
>>> vol = geoshade.VoxelVolume(np.arange(24, dtype=np.uint8).reshape(2, 3, 4), spacing=(1, 1, 2))
>>> img = to_pyvista(vol, selection=(5, 10))
>>> img.dimensions, img.spacing, int(img.cell_data["selected"].sum())
((5, 4, 3), (1.0, 1.0, 2.0), 6)
>>> back = from_pyvista(img)
>>> bool((back.data == vol.data).all()), back.spacing
(True, (1.0, 1.0, 2.0))
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

import numpy as np

from geoshade.errors import InputError, require
from geoshade.io.grids.lgr_interop import refined_to_pyvista
from geoshade.io.volumes.raw import native_order
from geoshade.models import CornerPointGrid, FieldSeries, StackModel, TriangleMesh, VoxelVolume
from geoshade.models.stacks import EMPTY, Legend
from geoshade.models.steps import resolve_step
from geoshade.models.volume import SUPPORTED_DTYPES

#: field_data key naming the geoshade model a dataset came from; its JSON metadata is in
#: :data:`META_KEY`
MODEL_KEY = "geoshade"
META_KEY = "geoshade_meta"
#: vtkDataSetAttributes.HIDDENCELL: the ghost-array bit of a blanked cell
HIDDEN_CELL = 32
#: VTK hexahedron corner order as (di, dj, dk) offsets
HEX_CORNERS = ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
               (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))
_GHOST = "vtkGhostType"
#: cell/point arrays VTK or PyVista add that are not model values
_VTK_ARRAYS = (_GHOST, "vtkOriginalCellIds", "vtkOriginalPointIds", "Normals")


def _pv():
    return require("pyvista", "pyvista", "converting to or from PyVista")


def _set_meta(ds, model: str, meta: dict) -> None:
    ds.field_data[MODEL_KEY] = [model]
    ds.field_data[META_KEY] = [json.dumps(meta)]


def _get_meta(ds) -> tuple[str, dict]:
    fd = ds.field_data
    if MODEL_KEY not in fd or META_KEY not in fd:
        return "", {}
    try:
        return str(fd[MODEL_KEY][0]), dict(json.loads(str(fd[META_KEY][0])))
    except (ValueError, TypeError, IndexError):
        raise InputError(f"PyVista dataset: field data {META_KEY!r} is not geoshade's JSON "
                         "metadata") from None


# ==============================================================================================
# to PyVista
# ==============================================================================================
def to_pyvista(model, **options):
    """A geoshade model as a PyVista dataset (see the module's table).

    Parameters
    ----------
    model : VoxelVolume, CornerPointGrid, FieldSeries, TriangleMesh or StackModel
    **options
        Those of the model's converter: :func:`volume_to_pyvista` (``name``, ``selection``),
        :func:`grid_to_pyvista` (``step``, ``z_up``), :func:`field_to_pyvista` (``step``),
        :func:`mesh_to_pyvista`, :func:`stacks_to_pyvista` (``include_empty``).

    Returns
    -------
    pyvista.DataSet

    Raises
    ------
    MissingExtraError
        PyVista is not installed (``pip install 'geoshade[pyvista]'``).
    InputError
        A model PyVista cannot hold, or a bad option.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> esg = to_pyvista(synthetic_grid(4, 3, 2))
    >>> type(esg).__name__, esg.n_cells, sorted(esg.cell_data.keys())[:3]
    ('ExplicitStructuredGrid', 24, ['FIPNUM', 'NTG', 'PERMX'])
    """
    converters: dict[type, Callable[..., Any]] = {
        VoxelVolume: volume_to_pyvista, CornerPointGrid: grid_to_pyvista,
        FieldSeries: field_to_pyvista, TriangleMesh: mesh_to_pyvista,
        StackModel: stacks_to_pyvista}
    for cls, convert in converters.items():
        if isinstance(model, cls):
            return convert(model, **options)
    raise InputError(f"to_pyvista: cannot convert a {type(model).__name__}; expected a "
                     "VoxelVolume, CornerPointGrid, FieldSeries, TriangleMesh or StackModel")


def volume_to_pyvista(volume: VoxelVolume, name: str | None = None, selection=None):
    """A volume as a ``pyvista.ImageData`` whose cells are the voxels.

    Parameters
    ----------
    volume : VoxelVolume
        A lazy (dask) volume is read here.
    name : str, optional
        Name of the cell array (default: ``meta["variable"]``, else ``"values"``).
    selection : (lo, hi), optional
        Also a uint8 cell array ``selected``: 1 where ``lo <= value <= hi`` (the core's
        selection, inclusive).

    Returns
    -------
    pyvista.ImageData
        ``dimensions`` = voxels + 1 along x, y, z; ``origin`` and ``spacing`` the volume's. The
        values array shares the volume's memory when it is a C-contiguous numpy array.

    Examples
    --------
    >>> import numpy as np
    >>> img = volume_to_pyvista(VoxelVolume(np.zeros((2, 3, 4), np.uint16), origin=(5, 0, 0)))
    >>> img.n_cells, img.origin, img.cell_data["values"].dtype.name
    (24, (5.0, 0.0, 0.0), 'uint16')
    """
    pv = _pv()
    nx, ny, nz = volume.shape_xyz
    data = native_order(volume.read_box())
    img = pv.ImageData(dimensions=(nx + 1, ny + 1, nz + 1), spacing=volume.spacing,
                       origin=volume.origin)
    arr = str(name or volume.meta.get("variable") or "values")
    img.cell_data[arr] = np.ascontiguousarray(data).reshape(-1)  # (nz, ny, nx): x fastest
    img.cell_data.active_scalars_name = arr
    if selection is not None:
        try:
            lo, hi = (float(v) for v in selection)
        except (TypeError, ValueError):
            raise InputError(f"selection: expected two numbers (lo, hi), got {selection!r}") \
                from None
        img.cell_data["selected"] = ((data >= lo) & (data <= hi)).astype(np.uint8).reshape(-1)
    _set_meta(img, "VoxelVolume", {"array": arr, "unit": volume.unit, "name": volume.name,
                                   "crs": str(volume.meta.get("crs", ""))})
    return img


def _pillar_xy(coord: np.ndarray, a: int, b: int, z: np.ndarray, dims) -> tuple:
    """x, y of corner (a, b) of every cell at depths ``z`` ((nx, ny, nz')): on its pillar,
    linear in z (the arithmetic of :meth:`CornerPointGrid.corners`)."""
    nx, ny = dims[0], dims[1]
    pil = coord[a:a + nx, b:b + ny][:, :, None, :]
    top, bot = pil[..., :3], pil[..., 3:]
    dz = bot[..., 2] - top[..., 2]
    t = np.where(dz != 0, (z - top[..., 2]) / np.where(dz != 0, dz, 1), 0.0)
    return top[..., 0] + t * (bot[..., 0] - top[..., 0]), top[..., 1] + t * (bot[..., 1]
                                                                            - top[..., 1])


def cell_points(grid: CornerPointGrid, z_up: bool = False) -> np.ndarray:
    """``(ncells * 8, 3)`` float64: the corners of every cell in VTK hexahedron order, cells
    i fastest, then j, k (the points of :func:`grid_to_pyvista`).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(3, 2, 2)
    >>> p = cell_points(g).reshape(2, 2, 3, 8, 3)            # k, j, i, corner, xyz
    >>> bool(np.allclose(p[1, 0, 2, 6], g.corners()[2, 0, 1, 7]))  # VTK 6 = geoshade 7
    True
    """
    nx, ny, nz = grid.dims
    coord = np.asarray(grid.coord, np.float64)
    pts = np.empty((nz, ny, nx, 8, 3), np.float64)
    for k0 in range(0, nz, max(1, (1 << 21) // max(1, nx * ny))):  # slabs of ~2e6 cells
        k1 = min(nz, k0 + max(1, (1 << 21) // max(1, nx * ny)))
        for c, (a, b, cc) in enumerate(HEX_CORNERS):
            z = np.asarray(grid.zcorn[a::2, b::2, 2 * k0 + cc:2 * k1:2], np.float64)
            x, y = _pillar_xy(coord, a, b, z, grid.dims)
            pts[k0:k1, :, :, c, 0] = x.T
            pts[k0:k1, :, :, c, 1] = y.T
            pts[k0:k1, :, :, c, 2] = -z.T if z_up else z.T
    return pts.reshape(-1, 3)


def _step_arrays(grid: CornerPointGrid, step) -> tuple[int | None, dict]:
    if not grid.steps or step is None:
        return None, {}
    k = resolve_step(step, len(grid.steps), dates=grid.step_dates,
                     reports=grid.meta.get("unrst_seqnum") or (), where=grid.name)
    return k, dict(grid.steps[k])


def grid_to_pyvista(grid: CornerPointGrid, step=-1, z_up: bool = False):
    """A corner-point grid as a ``pyvista.ExplicitStructuredGrid``.

    Parameters
    ----------
    grid : CornerPointGrid
    step : int or str, optional
        The report step whose keywords (SWAT, PRESSURE ...) become cell arrays beside the static
        properties: an index, -1 (the last, default), ``"R36"`` or a date; None: static
        properties only. Ignored for a grid without report steps.
    z_up : bool
        Negate z (depth, down positive in the grid's files) so that up is up in PyVista.

    Returns
    -------
    pyvista.ExplicitStructuredGrid
        ``dimensions`` ``(nx+1, ny+1, nz+1)``; cell ``i + nx*(j + ny*k)`` is cell (i, j, k);
        inactive cells hidden (ghost type HIDDENCELL); every property a cell array under its
        name (the arrays share the grid's memory where they are F-contiguous).  A grid with
        local grid refinements gives a ``pyvista.MultiBlock``: this grid under ``"GLOBAL"`` (its
        host cells hidden too) and each LGR's grid under its name
        (:func:`geoshade.io.grids.lgr_interop.refined_to_pyvista`).

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2)
    >>> esg = grid_to_pyvista(g, step=0)
    >>> hidden = int((esg.cell_data["vtkGhostType"] == HIDDEN_CELL).sum())
    >>> esg.dimensions, "SWAT" in esg.cell_data, hidden == g.ncells - g.nactive
    ((5, 4, 3), True, True)
    """
    pv = _pv()
    nx, ny, nz = grid.dims
    n = nx * ny * nz
    k, step_props = _step_arrays(grid, step)
    esg = pv.ExplicitStructuredGrid()
    esg.SetDimensions(nx + 1, ny + 1, nz + 1)
    esg.SetCells(pv.CellArray.from_regular_cells(np.arange(8 * n, dtype=np.int64
                                                           ).reshape(n, 8)))
    esg.points = cell_points(grid, z_up)
    for name, arr in {**grid.properties, **step_props}.items():
        a = native_order(np.asarray(arr))
        esg.cell_data[str(name)] = (a.astype(np.uint8) if a.dtype == bool else a).reshape(
            -1, order="F")
    ghost = np.where(grid.active, 0, HIDDEN_CELL).astype(np.uint8)
    esg.cell_data[_GHOST] = ghost.reshape(-1, order="F")
    meta = {"name": grid.name, "units": grid.units, "z_up": bool(z_up),
            "zcorn_dtype": np.dtype(grid.zcorn.dtype).name,
            "actnum_dtype": np.dtype(np.asarray(grid.actnum).dtype).name,
            "mapaxes": None if grid.mapaxes is None else [float(v) for v in grid.mapaxes],
            "step": k, "step_names": sorted(step_props),
            "step_date": grid.step_dates[k] if k is not None and k < len(grid.step_dates)
            else ""}
    _set_meta(esg, "CornerPointGrid", meta)
    esg.field_data["geoshade_coord"] = np.asarray(grid.coord, np.float64).reshape(-1)
    # local grid refinements: a MultiBlock of this grid (hosts hidden) and each LGR's cells
    return refined_to_pyvista(grid, esg, grid_to_pyvista, pv.MultiBlock, step=step, z_up=z_up)


def field_to_pyvista(field: FieldSeries, step=-1):
    """A field over time as a ``pyvista.ImageData`` (regular grids: node values as point data)
    or its corner-point grid's ``ExplicitStructuredGrid`` (values as cell data).

    Parameters
    ----------
    field : FieldSeries
    step : int, ``"all"`` or None
        The step shown (default -1, the last), as one array named after the field; ``"all"``:
        every step, arrays ``"NAME[k]"`` (k = 0 .. T-1).

    Examples
    --------
    >>> import numpy as np
    >>> f = FieldSeries(np.random.default_rng(0).random((3, 4, 5, 6)), name="SWAT")
    >>> img = field_to_pyvista(f, step="all")
    >>> img.dimensions, list(img.point_data.keys())
    ((6, 5, 4), ['SWAT[0]', 'SWAT[1]', 'SWAT[2]'])
    """
    name = field.name or "values"
    steps = (list(range(field.nsteps)) if isinstance(step, str) and step == "all"
             else [field.check_step(-1 if step is None else step)])
    every = isinstance(step, str) and step == "all"
    if field.grid is not None:
        ds = grid_to_pyvista(field.grid, step=None)
        _, meta = _get_meta(ds)
        target = ds.cell_data
    else:
        pv = _pv()
        nx, ny, nz = field.shape_xyz
        ds = (pv.RectilinearGrid(*field.axes()) if field.is_rectilinear else  # uneven nodes
              pv.ImageData(dimensions=(nx, ny, nz), spacing=field.spacing, origin=field.origin))
        meta = {}
        target = ds.point_data
    arrays = []
    for k in steps:
        arr = f"{name}[{k}]" if every else name
        target[arr] = np.ascontiguousarray(native_order(np.asarray(field.step(k)))).reshape(-1)
        arrays.append(arr)
    if field.active is not None and field.grid is None:
        target["active"] = np.asarray(field.active, np.uint8).reshape(-1)
    meta.update({"field": name, "unit": field.unit, "length_unit": field.length_unit,
                 "times": [field.times[k] for k in steps], "arrays": arrays,
                 "source": field.source})
    _set_meta(ds, "FieldSeries", meta)
    return ds


def mesh_to_pyvista(mesh: TriangleMesh):
    """A triangle mesh as ``pyvista.PolyData``: ``Normals`` and the values (named after the
    mesh, else ``"values"``) as point arrays.

    Examples
    --------
    >>> m = mesh_to_pyvista(TriangleMesh(np.eye(3), [[0, 1, 2]], values=[1, 2, 3], name="SWAT"))
    >>> m.n_cells, m.point_data["SWAT"].tolist()
    (1, [1.0, 2.0, 3.0])
    """
    pv = _pv()
    faces = np.empty((mesh.n_faces, 4), np.int64)
    faces[:, 0] = 3
    faces[:, 1:] = mesh.faces
    poly = pv.PolyData(np.asarray(mesh.vertices), faces=faces.reshape(-1))
    if mesh.normals is not None:
        poly.point_data["Normals"] = mesh.normals
        poly.point_data.active_normals_name = "Normals"
    name = mesh.name or "values"
    if mesh.values is not None:
        poly.point_data[name] = native_order(np.asarray(mesh.values))
    _set_meta(poly, "TriangleMesh", {"name": mesh.name, "array": name})
    return poly


def stacks_to_pyvista(model: StackModel, include_empty: bool = False):
    """A stack model as a ``pyvista.UnstructuredGrid`` of one hexahedron per interval.

    Exact whatever the intervals' heights (starts may lie between levels), which an
    ``ImageData`` of voxels is not; convert with :func:`geoshade.compute.stacks.
    stacks_to_voxels` first for voxels.

    Parameters
    ----------
    model : StackModel
    include_empty : bool
        Also the EMPTY intervals (air, gaps; code -1).

    Returns
    -------
    pyvista.UnstructuredGrid
        Cell arrays ``code`` (int32 material code), ``column`` (``ix + nx * iy``) and ``log``
        (uint8, 1 where the interval comes from a borehole log); the legend, the grid and the
        borehole columns in field data.

    Examples
    --------
    >>> m = StackModel([0, 2, 3], [0, 2.5, 1], [7, 8, 7], shape=(2, 1), nlevels=4)
    >>> ug = stacks_to_pyvista(m)
    >>> ug.n_cells, ug.cell_data["code"].tolist(), ug.bounds[4:]
    (3, [7, 8, 7], (0.0, 4.0))
    """
    pv = _pv()
    keep = np.ones(model.nintervals, bool) if include_empty else model.codes != EMPTY
    col = model.column_ids()[keep]
    lo, hi = model.starts[keep].astype(np.float64), model.ends()[keep].astype(np.float64)
    nx = model.shape[0]
    og, sp = np.asarray(model.origin), np.asarray(model.spacing)
    ix, iy = col % nx, col // nx
    xs = (og[0] + ix * sp[0], og[0] + (ix + 1) * sp[0])
    ys = (og[1] + iy * sp[1], og[1] + (iy + 1) * sp[1])
    zs = (og[2] + lo * sp[2], og[2] + hi * sp[2])
    n = col.size
    pts = np.empty((n, 8, 3))
    for c, (a, b, cc) in enumerate(HEX_CORNERS):
        pts[:, c, 0], pts[:, c, 1], pts[:, c, 2] = xs[a], ys[b], zs[cc]
    cells = np.arange(8 * n, dtype=np.int64).reshape(n, 8)
    ug = pv.UnstructuredGrid({pv.CellType.HEXAHEDRON: cells}, pts.reshape(-1, 3))
    ug.cell_data["code"] = native_order(np.asarray(model.codes[keep]))
    ug.cell_data["column"] = col
    ug.cell_data["log"] = model.log_intervals()[keep].astype(np.uint8)
    assert model.legend is not None and model.borehole is not None  # set by __post_init__
    _set_meta(ug, "StackModel", {
        "shape": list(model.shape), "nlevels": model.nlevels, "origin": list(model.origin),
        "spacing": list(model.spacing), "unit": model.unit, "crs": model.crs,
        "name": model.name, "legend": model.legend.to_dict(),
        "include_empty": bool(include_empty)})
    ug.field_data["geoshade_borehole"] = model.borehole.astype(np.uint8)
    ug.field_data["geoshade_log_base"] = model.log_base
    return ug


# ==============================================================================================
# from PyVista
# ==============================================================================================
def from_pyvista(dataset, name: str | None = None):
    """The geoshade model of a PyVista dataset, where one is defined.

    ``ImageData`` → :class:`VoxelVolume` (or the :class:`FieldSeries` it was made from),
    ``ExplicitStructuredGrid`` → :class:`CornerPointGrid` (or its FieldSeries),
    ``PolyData`` of triangles → :class:`TriangleMesh`, ``UnstructuredGrid`` made by
    :func:`stacks_to_pyvista` → :class:`StackModel`.

    Parameters
    ----------
    dataset : pyvista.DataSet
    name : str, optional
        ImageData: the array that becomes the volume (default: the one geoshade wrote, else the
        active scalars, else the first cell array, else the first point array).

    Raises
    ------
    InputError
        A dataset with no geoshade equivalent, or one that breaks the model's contract (not a
        corner-point layout, polygons that are not triangles, ...): one line saying why.

    Examples
    --------
    >>> import pyvista as pv
    >>> from_pyvista(pv.ImageData(dimensions=(3, 3, 3)).cast_to_structured_grid())
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: from_pyvista: a StructuredGrid has no geoshade model; ...
    """
    pv = _pv()
    kind, meta = _get_meta(dataset)
    if isinstance(dataset, pv.ImageData):
        if kind == "FieldSeries":
            return _field_from_image(dataset, meta)
        return volume_from_pyvista(dataset, name)
    if isinstance(dataset, pv.ExplicitStructuredGrid):
        grid = grid_from_pyvista(dataset)
        if kind == "FieldSeries":
            values = [np.asarray(dataset.cell_data[a]).reshape(grid.dims[::-1])
                      for a in meta["arrays"]]
            for a in meta["arrays"]:  # the field's steps are not grid properties
                grid.properties.pop(a, None)
            return FieldSeries(values, grid=grid, name=meta["field"], unit=meta["unit"],
                               length_unit=meta["length_unit"], times=meta["times"],
                               source=meta.get("source", ""))
        return grid
    if isinstance(dataset, pv.PolyData):
        return mesh_from_pyvista(dataset)
    if isinstance(dataset, pv.UnstructuredGrid) and kind == "StackModel":
        return stacks_from_pyvista(dataset)
    raise InputError(f"from_pyvista: a {type(dataset).__name__} has no geoshade model; "
                     "expected an ImageData, an ExplicitStructuredGrid, a PolyData of triangles "
                     "or an UnstructuredGrid made by to_pyvista(StackModel)")


def _values(arr, what: str) -> np.ndarray:
    a = np.asarray(arr)
    if a.ndim != 1:
        raise InputError(f"from_pyvista: array {what!r} has {a.shape[1]} components; expected "
                         "scalars")
    if a.dtype.name in SUPPORTED_DTYPES:
        return a
    if a.dtype == bool:
        return a.astype(np.uint8)
    if a.dtype.kind in "iu" and a.size:
        lo, hi = int(a.min()), int(a.max())
        for t in ("uint8", "int8", "uint16", "int16", "uint32", "int32"):
            if np.iinfo(t).min <= lo and hi <= np.iinfo(t).max:
                return a.astype(t)
    raise InputError(f"from_pyvista: array {what!r} has dtype {a.dtype}; a volume holds "
                     f"{', '.join(SUPPORTED_DTYPES)}")


def volume_from_pyvista(image, name: str | None = None) -> VoxelVolume:
    """A ``pyvista.ImageData`` as a :class:`VoxelVolume`.

    A cell array gives one voxel per cell (origin: the image's); a point array one voxel
    centred on each point (origin: the first point minus half a voxel). The values are shared
    with the dataset, not copied.

    Examples
    --------
    >>> import pyvista as pv
    >>> img = pv.ImageData(dimensions=(3, 2, 2), spacing=(2, 2, 2))
    >>> img.point_data["h"] = np.arange(12, dtype=np.float32)
    >>> v = volume_from_pyvista(img)
    >>> v.shape_xyz, v.origin, float(v.data[1, 1, 2])
    ((3, 2, 2), (-1.0, -1.0, -1.0), 11.0)
    """
    direction = np.asarray(image.direction_matrix, float)
    if not np.array_equal(direction, np.eye(3)):
        raise InputError("from_pyvista: the ImageData is rotated (direction matrix is not the "
                         "identity); a VoxelVolume is axis-aligned")
    kind, meta = _get_meta(image)
    cells, points = image.cell_data, image.point_data
    if name is None:
        cands = [meta.get("array")] if kind == "VoxelVolume" else []
        cands += [cells.active_scalars_name, *[a for a in cells.keys() if a not in _VTK_ARRAYS],
                  *[a for a in points.keys() if a not in _VTK_ARRAYS]]
        name = next((c for c in cands if c and (c in cells or c in points)), None)
        if name is None:
            raise InputError("from_pyvista: the ImageData has no cell or point array to make a "
                             "volume of")
    nx, ny, nz = (int(d) for d in image.dimensions)
    sp = tuple(float(s) for s in image.spacing)
    og = np.asarray(image.origin, float)
    if name in cells:
        shape, arr = (nz - 1, ny - 1, nx - 1), cells[name]
    elif name in points:
        shape, arr = (nz, ny, nx), points[name]
        og = og - np.asarray(sp) / 2
    else:
        have = ", ".join([*cells.keys(), *points.keys()]) or "none"
        raise InputError(f"from_pyvista: no array {name!r} in the ImageData; it has {have}")
    data = _values(arr, name).reshape(shape)
    return VoxelVolume(data, spacing=sp, origin=tuple(float(v) for v in og),  # type: ignore
                       unit=meta.get("unit", ""), name=meta.get("name", ""),
                       meta={"format": "pyvista", "variable": name,
                             **({"crs": meta["crs"]} if meta.get("crs") else {})})


def _field_from_image(image, meta: dict) -> FieldSeries:
    nx, ny, nz = (int(d) for d in image.dimensions)
    values = [np.asarray(image.point_data[a]).reshape(nz, ny, nx) for a in meta["arrays"]]
    active = (np.asarray(image.point_data["active"]).reshape(nz, ny, nx) != 0
              if "active" in image.point_data else None)
    return FieldSeries(values, spacing=tuple(float(s) for s in image.spacing),  # type: ignore
                       origin=tuple(float(v) for v in image.origin),  # type: ignore
                       active=active, name=meta["field"], unit=meta["unit"],
                       length_unit=meta["length_unit"], times=meta["times"],
                       source=meta.get("source", ""))


def _connectivity(ds) -> np.ndarray:
    from vtkmodules.util.numpy_support import vtk_to_numpy

    cells = ds.GetCells()
    conn = vtk_to_numpy(cells.GetConnectivityArray())
    offsets = vtk_to_numpy(cells.GetOffsetsArray())
    if offsets.size != ds.n_cells + 1 or (np.diff(offsets) != 8).any():
        raise InputError("from_pyvista: the ExplicitStructuredGrid has cells that are not "
                         "hexahedra")
    return conn.reshape(-1, 8)


def _pillars(x, y, z) -> tuple[np.ndarray, bool]:
    """COORD ((nx+1, ny+1, 6)) from the corner points ((2nx, 2ny, 2nz) each): the shallowest
    and deepest point on each pillar; and whether every corner lies on its pillar."""
    pad = [(1, 1), (1, 1), (0, 0)]
    X, Y, Z = (np.pad(a, pad, constant_values=np.nan) for a in (x, y, z))
    n0, n1, n2 = X.shape[0] // 2, X.shape[1] // 2, X.shape[2]

    def group(a):  # (pillar i, pillar j, every corner on it)
        return a.reshape(n0, 2, n1, 2, n2).transpose(0, 2, 1, 3, 4).reshape(n0, n1, -1)

    gx, gy, gz = group(X), group(Y), group(Z)
    top = np.nanargmin(gz, axis=2)[..., None]
    bot = np.nanargmax(gz, axis=2)[..., None]
    tb = [np.take_along_axis(g, ix, 2)[..., 0] for ix in (top, bot) for g in (gx, gy, gz)]
    coord = np.stack(tb, axis=-1)
    # every corner on the line through top and bottom (a vertical pillar when they coincide)
    d = coord[..., 3:] - coord[..., :3]
    dz = np.where(d[..., 2] != 0, d[..., 2], 1.0)
    t = np.where(d[..., 2:3] != 0, (gz - coord[..., 2:3]) / dz[..., None], 0.0)
    ex = coord[..., 0:1] + t * d[..., 0:1] - gx
    ey = coord[..., 1:2] + t * d[..., 1:2] - gy
    scale = max(1.0, float(np.nanmax(np.abs(coord[..., :2]))))
    with np.errstate(invalid="ignore"):
        off = np.nanmax(np.abs(np.concatenate([ex, ey], axis=2)))
    return coord, bool(not off > 1e-9 * scale)


def grid_from_pyvista(esg) -> CornerPointGrid:
    """A ``pyvista.ExplicitStructuredGrid`` as a :class:`CornerPointGrid`.

    The cells' corners give ZCORN; the pillars (COORD) are geoshade's own when it wrote the
    dataset, else the line through each pillar's shallowest and deepest corner, and every
    corner must lie on its pillar (a corner-point layout). Hidden cells (ghost type
    HIDDENCELL) are inactive; every other cell array is a property.

    Examples
    --------
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(4, 3, 2)
    >>> back = grid_from_pyvista(grid_to_pyvista(g, step=None))
    >>> bool(np.array_equal(back.corners(), g.corners())), sorted(back.properties)
    (True, ['FIPNUM', 'NTG', 'PERMX', 'PORO'])
    """
    kind, meta = _get_meta(esg)
    d = tuple(int(v) - 1 for v in esg.dimensions)
    nx, ny, nz = d
    if min(d) < 1 or esg.n_cells != nx * ny * nz:
        raise InputError(f"from_pyvista: ExplicitStructuredGrid dimensions {esg.dimensions} do "
                         f"not match its {esg.n_cells} cells")
    pts = np.asarray(esg.points, np.float64)[_connectivity(esg)]  # (ncells, 8, 3)
    pts = pts.reshape(nz, ny, nx, 8, 3)
    if meta.get("z_up"):
        pts = pts * np.array([1.0, 1.0, -1.0])
    x, y, z = (np.empty((2 * nx, 2 * ny, 2 * nz)) for _ in range(3))
    for c, (a, b, cc) in enumerate(HEX_CORNERS):
        for arr, q in ((x, 0), (y, 1), (z, 2)):
            arr[a::2, b::2, cc::2] = pts[..., c, q].T
    if "geoshade_coord" in esg.field_data and kind in ("CornerPointGrid", "FieldSeries"):
        coord = np.asarray(esg.field_data["geoshade_coord"], np.float64).reshape(nx + 1, ny + 1,
                                                                                  6)
    else:
        coord, on = _pillars(x, y, z)
        if not on:
            raise InputError("from_pyvista: the ExplicitStructuredGrid's corners do not lie on "
                             "straight pillars shared by the cells around them; it is not a "
                             "corner-point grid")
    zcorn = np.asfortranarray(z.astype(meta.get("zcorn_dtype", "float64")))
    ghost = esg.cell_data.get(_GHOST)
    hidden = (np.zeros(esg.n_cells, bool) if ghost is None
              else (np.asarray(ghost) & HIDDEN_CELL) != 0)
    act_dtype = meta.get("actnum_dtype", "int32")
    actnum = (~hidden).reshape((nx, ny, nz), order="F").astype(act_dtype)
    steps = set(meta.get("step_names", ()))
    props: dict[str, np.ndarray] = {}
    step: dict[str, np.ndarray] = {}
    for name in esg.cell_data.keys():
        if name in _VTK_ARRAYS:
            continue
        values = np.asarray(esg.cell_data[name])
        if values.ndim != 1:
            continue
        (step if name in steps else props)[name] = values.reshape((nx, ny, nz), order="F")
    return CornerPointGrid(coord, zcorn, actnum=actnum,
                           mapaxes=None if meta.get("mapaxes") is None
                           else np.asarray(meta["mapaxes"]), properties=props,
                           steps=[step] if step else [],
                           step_dates=[meta.get("step_date", "")] if step else [],
                           units=meta.get("units", ""), name=meta.get("name", ""),
                           meta={"format": "pyvista"})


def mesh_from_pyvista(poly) -> TriangleMesh:
    """A ``pyvista.PolyData`` of triangles as a :class:`TriangleMesh` (``Normals`` and the
    values back from their point arrays).

    Examples
    --------
    >>> import pyvista as pv
    >>> mesh_from_pyvista(pv.Plane(i_resolution=2, j_resolution=1).triangulate()).n_faces
    4
    >>> mesh_from_pyvista(pv.Plane(i_resolution=2, j_resolution=1))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: from_pyvista: the PolyData has faces that are not triangles; \
call .triangulate() first
    """
    kind, meta = _get_meta(poly)
    if poly.n_faces_strict == 0:
        raise InputError("from_pyvista: the PolyData has no polygons (a TriangleMesh needs "
                         "triangles)")
    if not poly.is_all_triangles:
        raise InputError("from_pyvista: the PolyData has faces that are not triangles; call "
                         ".triangulate() first")
    faces = np.asarray(poly.regular_faces, np.int64)
    pd = poly.point_data
    normals = np.asarray(pd["Normals"]) if "Normals" in pd else None
    name = meta.get("array") if kind == "TriangleMesh" else pd.active_scalars_name
    values = np.asarray(pd[name]) if name and name in pd and np.ndim(pd[name]) == 1 else None
    return TriangleMesh(np.asarray(poly.points), faces, normals=normals, values=values,
                        name=meta.get("name", "") if kind == "TriangleMesh" else (name or ""))


def stacks_from_pyvista(ug) -> StackModel:
    """The :class:`StackModel` of an ``UnstructuredGrid`` made by :func:`stacks_to_pyvista`
    (the intervals from the hexahedra's heights; EMPTY intervals are the gaps between them).

    Examples
    --------
    >>> m = StackModel([0, 2, 3], [0, 2.5, 1], [7, 8, 7], (2, 1), 4)
    >>> back = stacks_from_pyvista(stacks_to_pyvista(m))
    >>> back.starts.tolist(), back.codes.tolist()
    ([0.0, 2.5, 1.0], [7, 8, 7])
    """
    kind, meta = _get_meta(ug)
    if kind != "StackModel":
        raise InputError("from_pyvista: the UnstructuredGrid was not made by "
                         "to_pyvista(StackModel); its field data has no stack grid")
    codes = np.asarray(ug.cell_data["code"])
    keep = codes != EMPTY
    b = np.asarray(ug.points, np.float64).reshape(-1, 8, 3)[keep]
    nx, ny = (int(v) for v in meta["shape"])
    og, sp = np.asarray(meta["origin"], float), np.asarray(meta["spacing"], float)
    ix = np.floor((b[:, 0, 0] - og[0]) / sp[0] + 0.5).astype(np.int64)
    iy = np.floor((b[:, 0, 1] - og[1]) / sp[1] + 0.5).astype(np.int64)
    lo = ((b[:, 0, 2] - og[2]) / sp[2]).astype(np.float32)
    hi = ((b[:, 4, 2] - og[2]) / sp[2]).astype(np.float32)
    lg = meta["legend"]
    legend = Legend(np.asarray(lg["codes"], np.int64), tuple(lg["names"]),
                    np.asarray(lg["rgba"], np.uint8).reshape(-1, 4))
    fd = ug.field_data
    borehole = np.asarray(fd["geoshade_borehole"]) != 0 if "geoshade_borehole" in fd else None
    log_base = np.asarray(fd["geoshade_log_base"]) if "geoshade_log_base" in fd else None
    return StackModel.from_layers((nx, ny), int(meta["nlevels"]), column=ix + nx * iy,
                                  bottom=lo, top=hi, code=codes[keep], legend=legend,
                                  origin=tuple(og), spacing=tuple(sp), borehole=borehole,
                                  log_base=log_base, crs=meta.get("crs", ""),
                                  unit=meta.get("unit", ""), name=meta.get("name", ""))


__all__ = ["HEX_CORNERS", "HIDDEN_CELL", "cell_points", "field_to_pyvista", "from_pyvista",
           "grid_from_pyvista", "grid_to_pyvista", "mesh_from_pyvista", "mesh_to_pyvista",
           "stacks_from_pyvista", "stacks_to_pyvista", "to_pyvista", "volume_from_pyvista",
           "volume_to_pyvista"]

