"""The public entry points above the parts: ``load`` any model, ``view`` it with the right part.

::

    geoshade.load(path, **hints) ─▶ model ─▶ geoshade.view(model, **options) ─▶ View

:func:`view` picks the part by the model's type -- a :class:`~geoshade.models.VoxelVolume` is a
digital core, a :class:`~geoshade.models.CornerPointGrid` a reservoir grid, a
:class:`~geoshade.models.FieldSeries` an isosurface, a :class:`~geoshade.models.StackModel` (or a
labelled volume) geological stacks -- and ``as_`` overrides it where a model can be shown two
ways (``geoshade.view(grid, as_="iso", level=0.5)`` draws the SWAT isosurface of a grid).

>>> import geoshade
>>> geoshade.view_kind(geoshade.synthetic_core(8))
'core'
>>> with geoshade.view(geoshade.synthetic_core(16), select=(0, 9000), size=(32, 24)) as v:
...     img, stats = v.draw()
>>> stats["kind"], img.shape
('core', (24, 32, 4))
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from geoshade import io
from geoshade.core.plan import BRICKS_VM_EXTRA, core_routes
from geoshade.core.view import CoreView
from geoshade.errors import InputError
from geoshade.grid.plan import device_memory, grid_routes
from geoshade.grid.view import GridView
from geoshade.io import formats
from geoshade.io.interop import pyvista_io, xarray_io
from geoshade.io.plan import MARGIN, Machine, Plan, cpu_count, read_header
from geoshade.iso.view import IsoView
from geoshade.stacks.convert import convert
from geoshade.stacks.plan import stacks_routes
from geoshade.stacks.view import StacksView

#: the parts, in the order models are matched
KINDS = ("core", "grid", "iso", "stacks")
#: other names ``as_`` accepts
ALIASES = {"field": "iso", "isosurface": "iso", "volume": "core", "voxels": "core",
           "stack": "stacks", "cornerpoint": "grid"}


def _kind(as_) -> str:
    k = ALIASES.get(str(as_).lower(), str(as_).lower())
    if k not in KINDS:
        raise InputError(f"as: unknown part {as_!r}; expected one of {', '.join(KINDS)} (or "
                         f"{', '.join(ALIASES)})")
    return k


def distributed_class(kind: str) -> type:
    """The View that draws part ``kind`` on a dask cluster (``distributed=True`` with a
    ``scheduler``): the part's own View, whose backend is then the cluster's
    (:class:`~geoshade.core.distributed.ClusterBricks`: a core's bricks;
    :class:`~geoshade.grid.distributed.ClusterFaces`: a grid's layer ranges); one line for a
    part that draws in one process only."""
    k = _kind(kind)
    if k in ("core", "grid"):
        return view_class(k)
    raise InputError(f"distributed: the {k} view draws in one process; the core and the grid "
                     "draw on a cluster")


def view_class(kind: str):
    """The View class of part ``kind`` (``core grid iso stacks``)."""
    k = _kind(kind)
    if k == "core":

        return CoreView
    if k == "grid":

        return GridView
    if k == "iso":

        return IsoView

    return StacksView


def view_kind(model, as_=None) -> str:
    """The part that shows ``model`` (``as_`` forces one, which must accept it)."""
    if as_ is not None:
        k = _kind(as_)
        if not view_class(k).accepts(model):
            raise InputError(f"as: the {k} view cannot show a {type(model).__name__}")
        return k
    for k in KINDS:
        if view_class(k).accepts(model):
            return k
    raise InputError(f"view: nothing shows a {type(model).__name__}; geoshade shows voxel "
                     "volumes (core), corner-point grids (grid), fields over time (iso) and "
                     "stack models (stacks)")


def view(model, as_=None, **options):
    """The View of the part that shows ``model``.

    Parameters
    ----------
    model : VoxelVolume, CornerPointGrid, FieldSeries or StackModel
        (a path is read with :func:`load` first, with ``as_``).
    as_ : {'core', 'grid', 'iso', 'stacks'} or 'field', optional
        Force a part: ``as_="iso"`` shows a grid's report-step keyword as an isosurface,
        ``as_="stacks"`` a labelled volume as stacks.
    **options
        The part's options (``ctx``, ``progress`` too); all of them are checked before any
        GL context is created.  ``distributed=True`` with ``scheduler=`` draws a core or a
        grid on a ``dask.distributed`` cluster (:func:`distributed_class`).

    Returns
    -------
    View
        :class:`~geoshade.core.CoreView`, :class:`~geoshade.grid.GridView`,
        :class:`~geoshade.iso.IsoView` or :class:`~geoshade.stacks.StacksView`; use it with
        ``with``, ``draw()``, ``update(...)`` and ``release()``.
    """
    if isinstance(model, str | Path):
        model = load(model, as_=as_)
    kind = view_kind(model, as_)
    if options.get("distributed"):  # bricks or layer ranges on a dask cluster
        return distributed_class(kind)(model, **options)
    return view_class(kind)(model, **options)


def load(path, as_=None, **hints) -> Any:
    """Read any file geoshade reads into its model (see :func:`geoshade.io.load`).

    ``as_="field"`` (or ``"iso"``) reads fields over time (:func:`geoshade.io.load_field`:
    ``keyword``, ``color_by``, ``step``, ``spacing`` hints), so an ECLIPSE case or an array
    file becomes a :class:`~geoshade.models.FieldSeries`; ``as_="stacks"`` converts a labelled
    volume to a :class:`~geoshade.models.StackModel` (a georeferenced one-band GeoTIFF, a DEM,
    is read so by default: a terrain model, as is every kind of file of the ``terrain`` domain
    of :mod:`geoshade.io.formats`); ``as_="grid"``/``"core"`` check that the
    file is that kind of model; ``as_="summary"`` reads the summary vectors of the ECLIPSE/OPM
    case of any of its files (``CASE.SMSPEC``, ``.DATA``, ``.EGRID`` ...; ``vectors=["FOPR",
    "WOPR:*"]`` keeps some) into a :class:`~geoshade.models.summary_vectors.SummaryTable`
    (``.to_pandas()``, ``.to_xarray()``).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> np.save(os.path.join(d, "v.npy"), np.zeros((4, 5, 6), np.float32))
    >>> np.save(os.path.join(d, "s.npy"), np.zeros((3, 4, 5, 6), np.float32))
    >>> type(load(os.path.join(d, "v.npy"))).__name__       # read either way: a volume
    'VoxelVolume'
    >>> load(os.path.join(d, "v.npy"), as_="field").nsteps  # or a field of one step
    1
    >>> load(os.path.join(d, "s.npy")).nsteps               # (time, z, y, x): only a field
    3
    """
    if as_ is None:
        fmt = formats.find(path)
        if fmt is not None and fmt.domain == "terrain":  # a DEM is a terrain (stacks) model
            as_ = "stacks"
    if as_ is None:
        return io.load(path, **hints)
    if str(as_).lower() == "summary":  # the vectors over time of any file of a case
        return next(f for f in formats.FORMATS if f.name == "summary").function()(path, **hints)
    k = _kind(as_)
    if k == "iso":
        return io.load_field(path, **hints)
    if k == "stacks":
        return convert(path, **hints)
    model = io.load(path, **hints)
    if not view_class(k).accepts(model):
        raise InputError(f"{path}: not a {k} model (it reads as a {type(model).__name__})")
    return model


#: the part that draws each kind of header (:class:`geoshade.io.plan.Header`)
PLAN_PARTS = {"volume": "core", "volume-store": "core", "grid": "grid", "grid-store": "grid",
              "stacks": "stacks"}


def plan(path, as_=None, options=None, memory: int | None = None,
         gpu_memory: int | None = None, machine: Machine | None = None,
         **hints) -> Plan | None:
    """The memory plan of drawing ``path``, made from its header alone, before anything is
    loaded: every route (in memory, from a store, a store's coarse level or pyramid level, in
    bricks, on a cluster) with its resident memory, address space and GPU bytes, whether each
    fits this machine, and the route taken (:class:`geoshade.io.plan.Plan`); None where the
    file's header says nothing (its kind has no ``header`` function) or another part draws it.

    Parameters
    ----------
    path : str or Path
    as_ : {'core', 'grid', 'stacks'}, optional
        The part that will draw it (default: by the header's kind).
    options : the part's options object (parsed), optional
        What the picture is: the core's ``box`` and ``method``, the grid's approach,
        ``distributed``...
    memory : int, optional
        The RAM budget (bytes); default: what this machine has available.
    gpu_memory : int, optional
        The GPU's memory (bytes); default: ``nvidia-smi``'s free memory where there is one.
    machine : Machine, optional
        The figures to plan for instead of this process's (``memory`` and ``gpu_memory`` are
        then not used): what another machine, or this one under ``ulimit -v``, would do.
    **hints
        Reading hints (a raw file's ``shape`` and ``dtype``...).

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "v.npy")
    >>> np.save(f, np.zeros((64, 64, 64), np.uint8))
    >>> p = plan(f, memory=64 << 20)
    >>> [r.name for r in p.routes], p.chosen is None
    (['memory', 'bricks', 'level'], True)
    >>> plan(f).chosen.name
    'memory'
    """
    header = read_header(path, **hints)
    if header is None:
        return None
    kind = PLAN_PARTS.get(header.kind)
    if kind is None or (as_ is not None and _kind(as_) != kind):
        return None
    if machine is None:
        source = "--gpu-memory" if gpu_memory is not None else ""
        if gpu_memory is None:
            gpu_memory, source = device_memory()
            source = source if gpu_memory is not None else ""
        machine = Machine.here(memory=memory, gpu=gpu_memory, gpu_source=source)
    if kind == "core":   # what a bricks route may use: the plan's margin taken
        cap = None if machine.ram is None else int(machine.ram / MARGIN)
        if machine.address_space is not None:
            room = int(machine.address_space / MARGIN) - BRICKS_VM_EXTRA
            cap = room if cap is None else min(cap, room)
        routes = core_routes(header, options, cap)
    elif kind == "grid":
        sched = getattr(options, "scheduler", None)
        workers = getattr(sched, "workers", 0) or min(2, cpu_count())
        routes = grid_routes(header, options, workers=workers)
    else:
        routes = stacks_routes(header, options)
    if not routes:
        return None
    forced = "cluster" if getattr(options, "distributed", False) else None
    if forced is not None and not any(r.name == forced for r in routes):
        return None   # drawn on a cluster, which this part plans nothing for
    hint = ("the whole volume is drawn without a --box: give a --box (or a coarser --level) "
            "to draw a part of it" if kind == "core" and getattr(options, "box", None) is None
            else "")
    return Plan(header, machine, routes, forced=forced, hint=hint)


def to_pyvista(model, **options):
    """A model as a PyVista dataset (the ``pyvista`` extra): a volume as ``ImageData`` (voxels
    are cells), a corner-point grid as ``ExplicitStructuredGrid`` (inactive cells hidden), a
    field, an isosurface mesh as ``PolyData``, a stack model as an ``UnstructuredGrid`` of its
    intervals. See :mod:`geoshade.io.interop.pyvista_io` for the options and the exact layout.

    Examples
    --------
    >>> import geoshade
    >>> img = geoshade.to_pyvista(geoshade.synthetic_core(8), selection=(0, 9000))
    >>> img.n_cells, "selected" in img.cell_data
    (512, True)
    >>> geoshade.from_pyvista(img).shape_xyz
    (8, 8, 8)
    """
    return pyvista_io.to_pyvista(model, **options)


def from_pyvista(dataset, name: str | None = None):
    """The model of a PyVista dataset where one is defined (``ImageData`` → volume,
    ``ExplicitStructuredGrid`` → corner-point grid, ``PolyData`` of triangles → mesh, a stack
    model's ``UnstructuredGrid`` → stacks); see
    :func:`geoshade.io.interop.pyvista_io.from_pyvista`."""
    return pyvista_io.from_pyvista(dataset, name=name)


def to_xarray(model, name: str | None = None):
    """A model as xarray (the ``netcdf`` extra): a volume or field as a ``DataArray`` with
    coordinates and units, a corner-point grid as a ``Dataset`` (its properties carry their
    ECLIPSE units in ``attrs["units"]``, as ``model.to_xarray()`` does); see
    :mod:`geoshade.io.interop.xarray_io`.

    Examples
    --------
    >>> import geoshade
    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> ds = geoshade.to_xarray(synthetic_grid(4, 3, 2))
    >>> ds["PERMX"].attrs["units"], ds["SWAT"].dims
    ('mD', ('time', 'k', 'j', 'i'))
    """
    return xarray_io.to_xarray(model, name=name)


def from_xarray(obj, grid=None, name: str | None = None):
    """The model of an xarray ``DataArray`` or ``Dataset`` (a volume, a field, a field on
    ``grid``, or a grid); see :func:`geoshade.io.interop.xarray_io.from_xarray`."""
    return xarray_io.from_xarray(obj, grid=grid, name=name)



__all__ = ["ALIASES", "KINDS", "PLAN_PARTS", "distributed_class", "from_pyvista", "from_xarray",
           "load", "plan", "to_pyvista", "to_xarray", "view", "view_class", "view_kind"]
