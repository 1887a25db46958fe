"""Georeferenced rasters through rasterio: DEMs (one band of heights) and drape images (RGB/RGBA
orthophotos and maps).

The kinds of raster read as terrain are the ``terrain`` rows of :mod:`geoshade.io.formats`:
a one-band GeoTIFF, an Arc ASCII grid ``.asc`` (its CRS from a ``.prj`` beside it) and an SRTM
tile ``.hgt`` or ``.hgt.zip`` (its place from its name, ``N46E008.hgt``; EPSG:4326).

- :func:`read_dem`: any of them (any one-band raster rasterio opens) → :class:`Raster`:
  heights ``(ny, nx) float64`` with the nodata cells as NaN, **row 0 south** (the layout of a
  :class:`~geoshade.models.stacks.StackModel`'s columns, ``c = ix + nx·iy``), the lower-left
  corner, the cell size, the CRS and the nodata value.
- :func:`resample`: a raster onto another grid (origin, cell size, shape, CRS) with
  ``rasterio.warp.reproject``, NaN where it has no data.
- :func:`drape_for`: an RGB(A) image placed by its georeference on a model's grid, cropped and
  resampled to its extent; the fraction of the grid it covers.
- :func:`is_georeferenced`: a file of a terrain row, or a TIFF with GeoTIFF tags (tifffile
  only, no rasterio).
- :func:`describe_dem`: what ``geoshade info DEM.tif`` prints.

A raster without a CRS whose extent looks like longitudes and latitudes (:func:`looks_like_degrees`)
is taken as EPSG:4326 and reprojected like a geographic one; the note says it was assumed (the
picture, the JSON and ``info`` show it), so cells of degrees are never drawn as metres.

A raster on a rotated (or sheared) grid — an affine transform with rotation terms — is placed
with its rotation: :func:`unrotate` resamples it by ``rasterio.warp.reproject`` onto a north-up
grid over its footprint (bilinear, NaN outside it), and ``meta["rotated"]`` says so; a rotated
drape is placed by the same warp. rasterio is the optional extra ``geo``.
"""

from __future__ import annotations

import math
import warnings
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import tifffile

from geoshade.errors import InputError, require
from geoshade.io import formats
from geoshade.io.paths import check_file, check_memory, one_line

#: TIFF tags that make a TIFF a GeoTIFF (ModelPixelScale, ModelTiepoint, ModelTransformation,
#: GeoKeyDirectory)
GEO_TAGS = (33550, 33922, 34264, 34735)
#: largest side of a drape texture (pixels)
MAX_DRAPE_SIDE = 4096
#: a raster without CRS is taken as degrees when its extent fits longitudes and latitudes and its
#: cells are smaller than this (0.1° is about 11 km)
DEGREE_CELL = 0.1
#: the CRS assumed for such a raster
ASSUMED_GEOGRAPHIC = "EPSG:4326"


def _rasterio():
    return require("rasterio", "geo", "reading GeoTIFF DEMs and drapes")


@dataclass
class Raster:
    """A georeferenced one-band raster on an axis-aligned grid.

    data:    (ny, nx) float64   values, NaN = nodata; row 0 is the **southern** row
    origin:  (x0, y0)           lower-left corner of cell (0, 0) (world units of the CRS)
    spacing: (dx, dy)           cell size, both > 0
    crs:     str                ``EPSG:28992``, WKT, or ``""`` when the file has none
    nodata:  float or None      the file's nodata value
    name:    str                file name
    unit:    str                vertical unit when the file says (``metre``), else ``""``
    """

    data: np.ndarray
    origin: tuple[float, float]
    spacing: tuple[float, float]
    crs: str = ""
    nodata: float | None = None
    name: str = ""
    unit: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def shape(self) -> tuple[int, int]:
        """(nx, ny)."""
        return int(self.data.shape[1]), int(self.data.shape[0])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax)."""
        (x0, y0), (dx, dy), (nx, ny) = self.origin, self.spacing, self.shape
        return (x0, y0, x0 + nx * dx, y0 + ny * dy)

    def transform(self):
        """The rasterio ``Affine`` of the north-up grid (row 0 north)."""
        x0, _, _, y1 = self.bounds
        return _affine(x0, y1, self.spacing[0], self.spacing[1])


def grid_transform(origin, spacing, shape):
    """The north-up rasterio ``Affine`` of a grid given by its lower-left ``origin (x0, y0)``,
    ``spacing (dx, dy)`` and ``shape (nx, ny)``."""
    _rasterio()
    return _affine(float(origin[0]), float(origin[1]) + shape[1] * float(spacing[1]),
                   float(spacing[0]), float(spacing[1]))


def _affine(x0: float, y_top: float, dx: float, dy: float):
    from affine import Affine

    return Affine(dx, 0.0, x0, 0.0, -dy, y_top)


#: the CRS given to both sides of a resampling when neither grid has one (no transformation)
_LOCAL = "EPSG:3857"


def _terrain_file(p: Path) -> bool:
    """A file of a terrain row of the format table decided by its name (``.asc``, ``.hgt``)."""
    fmt = formats.find(p, sniff=False)
    return fmt is not None and fmt.domain == "terrain" and fmt.test is None and p.is_file()


def is_georeferenced(path) -> bool:
    """True for a raster placed on the ground: a file of a ``terrain`` row of the format table
    known by its name (Arc ASCII ``.asc``, SRTM ``.hgt``/``.hgt.zip``), or a TIFF carrying
    GeoTIFF tags (read with tifffile; rasterio not needed).

    >>> import tempfile, os, numpy as np, tifffile
    >>> f = os.path.join(tempfile.mkdtemp(), "plain.tif")
    >>> tifffile.imwrite(f, np.zeros((2, 2), np.uint8))
    >>> is_georeferenced(f)
    False
    """
    p = Path(path)
    if _terrain_file(p):
        return True
    if p.suffix.lower() not in (".tif", ".tiff") or not p.is_file():
        return False

    try:
        with tifffile.TiffFile(p) as tf:
            tags = getattr(tf.pages[0], "tags", None)
            return tags is not None and any(tags.get(t) is not None for t in GEO_TAGS)
    except Exception:  # not a TIFF: the caller's reader says so
        return False


def is_dem(path) -> bool:
    """True for a raster of heights: a file of a ``terrain`` row known by its name, or a
    georeferenced TIFF of one band (:func:`geoshade.load` makes it a terrain model), not an
    orthophoto to drape.

    >>> import tempfile, os, numpy as np, tifffile
    >>> f = os.path.join(tempfile.mkdtemp(), "plain.tif")
    >>> tifffile.imwrite(f, np.zeros((2, 2), np.float32))
    >>> is_dem(f)
    False
    """
    if _terrain_file(Path(path)):
        return True
    if not is_georeferenced(path):
        return False
    try:
        with tifffile.TiffFile(path) as tf:
            return int(getattr(tf.pages[0], "samplesperpixel", 1)) == 1
    except Exception:  # unreadable: the reader says why
        return False


def _crs_text(crs) -> str:
    if crs is None:
        return ""
    try:
        epsg = crs.to_epsg()
    except Exception:  # pragma: no cover - odd CRS
        epsg = None
    return f"EPSG:{epsg}" if epsg else crs.to_string()


def _open(path, what: str):
    rasterio = _rasterio()
    p = check_file(path, what)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # NotGeoreferencedWarning: checked below
            try:
                return rasterio.open(p)
            except Exception:
                inner = _zipped_raster(p)  # a zipped tile named unlike its member
                if inner is None:
                    raise
                return rasterio.open(inner)
    except Exception as exc:  # rasterio raises RasterioIOError and friends
        raise InputError(f"{path}: not a raster rasterio can read ({one_line(exc)}); "
                         f"expected {what}") from None


def _zipped_raster(p: Path) -> str | None:
    """``/vsizip/`` path of the one raster in a ``.zip`` (None: not a zip of one raster)."""
    if p.suffix.lower() != ".zip" or not zipfile.is_zipfile(p):
        return None
    with zipfile.ZipFile(p) as zf:
        names = [n for n in zf.namelist() if formats.find(n, sniff=False) is not None
                 and not n.endswith("/")]
    return f"/vsizip/{p.resolve()}/{names[0]}" if len(names) == 1 else None


def looks_like_degrees(bounds, spacing) -> bool:
    """Whether a grid's extent ``(xmin, ymin, xmax, ymax)`` fits longitudes (-180..180) and
    latitudes (-90..90) and its cells are under :data:`DEGREE_CELL`: how degrees look.

    >>> looks_like_degrees((8.0, 46.0, 9.0, 47.0), (1 / 1200, 1 / 1200))
    True
    >>> looks_like_degrees((155000.0, 463000.0, 156000.0, 464000.0), (5.0, 5.0))
    False
    """
    x0, y0, x1, y1 = (float(v) for v in bounds)
    return (max(abs(x0), abs(x1)) <= 180 and max(abs(y0), abs(y1)) <= 90
            and 0 < max(float(spacing[0]), float(spacing[1])) < DEGREE_CELL)


def _checked_transform(src, path):
    """The raster's affine transform; a degenerate one (zero cell size, columns parallel to
    rows) is one line."""
    t = src.transform
    if abs(t.a * t.e - t.b * t.d) < 1e-300 or (t.a == 0 and t.b == 0) or (t.d == 0 and t.e == 0):
        raise InputError(f"{path}: transform has a zero cell size; expected a georeferenced "
                         "raster")
    return t


def is_rotated(t) -> bool:
    """Whether an affine transform turns the grid (rotation or shear terms)."""
    return t.b != 0 or t.d != 0


def footprint(t, width: int, height: int) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of the four corners of a ``width × height`` raster under the
    affine ``t`` (rotated or not).

    >>> from affine import Affine
    >>> footprint(Affine.rotation(90) @ Affine.scale(2), 3, 1)
    (-2.0, 0.0, 0.0, 6.0)
    """
    pts = [t @ (c, r) for c, r in ((0, 0), (width, 0), (0, height), (width, height))]
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return (float(min(xs)), float(min(ys)), float(max(xs)), float(max(ys)))


def unrotate(values: np.ndarray, t, crs: str = "", what: str = ""):
    """A raster on a rotated (or sheared) grid resampled onto a north-up grid over its
    footprint, by ``rasterio.warp.reproject`` (bilinear; NaN outside the rotated grid).

    ``values`` are the pixels as ``t`` places them (row 0 at ``t``'s origin). Returns
    ``(heights (ny, nx) row 0 south, origin (x0, y0), spacing (d, d), note)``; the cells are
    square, as small as the source's smaller side.

    Examples
    --------
    >>> from affine import Affine
    >>> t = Affine.translation(100, 200) @ Affine.rotation(30) @ Affine.scale(10, -10)
    >>> z, origin, spacing, note = unrotate(np.ones((4, 6)), t)
    >>> z.shape, spacing, note
    ((7, 8), (10.0, 10.0), 'rotated 30°: resampled north-up, bilinear (8×7 cells of 10)')
    """
    _rasterio()
    from rasterio.warp import Resampling, reproject  # type: ignore[import-untyped, unused-ignore]

    h, w = values.shape
    x0, y0, x1, y1 = footprint(t, w, h)
    d = float(min(math.hypot(t.a, t.d), math.hypot(t.b, t.e)))
    nx = max(1, math.ceil((x1 - x0) / d - 1e-9))
    ny = max(1, math.ceil((y1 - y0) / d - 1e-9))
    check_memory(nx * ny * 8 * 2, what or "raster", f"the {nx}×{ny} north-up grid of a "
                 "rotated raster")
    out = np.full((ny, nx), np.nan, np.float64)
    reproject(np.ascontiguousarray(values, np.float64), out, src_transform=t,
              src_crs=crs or _LOCAL, src_nodata=np.nan, dst_transform=_affine(x0, y1, d, d),
              dst_crs=crs or _LOCAL, dst_nodata=np.nan, resampling=Resampling.bilinear,
              # the exact transform per pixel, and the 2×2 bilinear kernel (GDAL widens it
              # where a turned grid looks coarser along x or y): bilinear in the grid's frame
              XSCALE=1, YSCALE=1, tolerance=0)
    angle = math.degrees(math.atan2(t.d, t.a))
    note = f"rotated {angle:.4g}°: resampled north-up, bilinear ({nx}×{ny} cells of {d:.4g})"
    return np.ascontiguousarray(out[::-1]), (x0, y1 - ny * d), (d, d), note


def utm_crs(lon: float, lat: float) -> str:
    """The WGS 84 UTM zone of a point: ``EPSG:326zz`` north of the equator, ``EPSG:327zz``
    south.

    >>> utm_crs(5.2, 52.1), utm_crs(-70.6, -33.4), utm_crs(180.0, 0.0)
    ('EPSG:32631', 'EPSG:32719', 'EPSG:32660')
    """
    zone = min(60, max(1, math.floor((float(lon) + 180.0) / 6.0) + 1))
    return f"EPSG:{(32600 if lat >= 0 else 32700) + zone}"


def to_projected(raster: Raster, what: str = "") -> Raster:
    """A raster in a geographic CRS (degrees; EPSG:4326, how SRTM ships) reprojected by
    ``rasterio.warp`` onto a north-up grid in the UTM zone of its centre (metres), bilinear,
    nodata kept as NaN; ``meta["reprojected"]`` holds the one-line note that says so (the
    picture, the JSON and stderr show it). A projected raster is returned as it is.

    Examples
    --------
    >>> r = Raster(np.arange(12.0).reshape(3, 4), (5.0, 52.0), (0.01, 0.01), "EPSG:4326")
    >>> p = to_projected(r)
    >>> p.crs, round(p.spacing[0]), p.meta["reprojected"][:36]
    ('EPSG:32631', 864, 'reprojected from EPSG:4326 (degrees)')
    """
    from rasterio.crs import CRS  # type: ignore[import-untyped, unused-ignore]
    from rasterio.warp import (  # type: ignore[import-untyped, unused-ignore]
        Resampling,
        calculate_default_transform,
        reproject,
        transform,
    )

    _rasterio()
    if not raster.crs or not CRS.from_user_input(raster.crs).is_geographic:
        return raster
    x0, y0, x1, y1 = raster.bounds
    (lon,), (lat,) = transform(raster.crs, "EPSG:4326", [(x0 + x1) / 2], [(y0 + y1) / 2])
    dst = utm_crs(lon, lat)
    nx, ny = raster.shape
    t, w, h = calculate_default_transform(raster.crs, dst, nx, ny, x0, y0, x1, y1)
    d = float(max(abs(t.a), abs(t.e)))   # square cells
    t, w, h = calculate_default_transform(raster.crs, dst, nx, ny, x0, y0, x1, y1,
                                          resolution=(d, d))
    check_memory(int(w) * int(h) * 8 * 2, what or raster.name, f"the {w}×{h} reprojected DEM")
    out = np.full((h, w), np.nan, np.float64)
    reproject(np.ascontiguousarray(raster.data[::-1]), out, src_transform=raster.transform(),
              src_crs=raster.crs, src_nodata=np.nan, dst_transform=t, dst_crs=dst,
              dst_nodata=np.nan, resampling=Resampling.bilinear)
    zone = int(dst.split(":")[1]) % 100
    note = (f"reprojected from {raster.crs} (degrees) to {dst} (UTM zone {zone}"
            f"{'N' if dst.startswith('EPSG:326') else 'S'}, the DEM's centre): {w}×{h} cells "
            f"of {d:.4g} m")
    if raster.meta.get("assumed_crs"):   # the file has no CRS: say what was taken
        note = f"{raster.meta['assumed_crs']}; {note}"
    meta = {**raster.meta, "geographic": False, "reprojected": note,
            "source_crs": raster.crs}
    return Raster(np.ascontiguousarray(out[::-1]), (float(t.c), float(t.f) - h * d), (d, d),
                  dst, raster.nodata, raster.name, raster.unit, meta)


def read_dem(path, band: int = 1, project: bool = True) -> Raster:
    """Read a DEM (one band of heights) with rasterio.

    Parameters
    ----------
    path : path
        GeoTIFF, Arc ASCII ``.asc``, SRTM ``.hgt``/``.hgt.zip`` (any one-band raster rasterio
        reads; a zip of one raster too).
    band : int
        Band to read (1-based); a file with several bands is refused unless one is chosen.
    project : bool
        A DEM in a geographic CRS (degrees, as SRTM ships) is reprojected to the UTM zone of
        its centre (:func:`to_projected`, one warning with the note); False keeps degrees. A
        DEM without CRS whose extent looks like degrees (:func:`looks_like_degrees`) is taken
        as EPSG:4326, and ``meta["assumed_crs"]`` (and the note) say so.

    Returns
    -------
    Raster
        Heights as float64, nodata (the file's nodata value, its mask, NaN) as NaN, row 0 south.

    Raises
    ------
    InputError
        Not a raster, several bands (an RGB image is a drape, not a DEM), a rotated grid, no
        finite height.

    Examples
    --------
    >>> import tempfile, os, numpy as np, rasterio
    >>> from affine import Affine
    >>> f = os.path.join(tempfile.mkdtemp(), "dem.tif")
    >>> z = np.array([[3, 4], [1, -9999]], np.float32)
    >>> with rasterio.open(f, "w", driver="GTiff", width=2, height=2, count=1, dtype="float32",
    ...                    crs="EPSG:28992", transform=Affine(10, 0, 100, 0, -10, 220),
    ...                    nodata=-9999) as dst:
    ...     dst.write(z, 1)
    >>> d = read_dem(f)
    >>> d.data.tolist(), d.origin, d.spacing, d.crs
    ([[1.0, nan], [3.0, 4.0]], (100.0, 200.0), (10.0, 10.0), 'EPSG:28992')
    """
    with _open(path, "a DEM (a one-band GeoTIFF of heights)") as src:
        if src.count < 1:
            raise InputError(f"{path}: no band; expected a DEM with one band of heights")
        if band == 1 and src.count > 1:
            raise InputError(f"{path}: {src.count} bands; a DEM has one band of heights "
                             "(an RGB image is a drape: --drape)")
        if not 1 <= band <= src.count:
            raise InputError(f"{path}: band {band} missing; the file has {src.count}")
        t = _checked_transform(src, path)
        check_memory(src.width * src.height * 8 * 2, path, f"the {src.width}×{src.height} DEM")
        try:
            arr = src.read(band, masked=True, out_dtype="float64")
        except Exception as exc:
            raise InputError(f"{path}: cannot read band {band} ({one_line(exc)})") from None
        crs, nodata = _crs_text(src.crs), src.nodata
        geographic = bool(src.crs is not None and src.crs.is_geographic)
        units = src.units[band - 1] if src.units else ""
        dtype = src.dtypes[band - 1]
    if not np.issubdtype(np.dtype(dtype), np.number) or np.issubdtype(np.dtype(dtype),
                                                                         np.complexfloating):
        raise InputError(f"{path}: band {band} is {dtype}; expected numbers (heights)")
    data = np.ma.filled(arr, np.nan)
    data[~np.isfinite(data)] = np.nan
    if not np.isfinite(data).any():
        raise InputError(f"{path}: every cell is nodata; expected heights")
    meta = {"source": str(path), "dtype": str(dtype), "geographic": geographic}
    if is_rotated(t):   # placed with its rotation: warped onto a north-up grid over it
        data, (x0, y0), (dx, dy), meta["rotated"] = unrotate(data, t, crs, str(path))
        ny, nx = data.shape
        y_top = y0 + ny * dy
    else:
        nx, ny = data.shape[1], data.shape[0]
        dx, dy = abs(float(t.a)), abs(float(t.e))
        x0 = float(t.c) if t.a > 0 else float(t.c) - nx * dx
        y_top = float(t.f) if t.e < 0 else float(t.f) + ny * dy
        if t.a < 0:
            data = data[:, ::-1]
        if t.e < 0:  # north-up: row 0 north -> flip to row 0 south
            data = data[::-1]
        data = np.ascontiguousarray(data)
    bounds = (x0, y_top - ny * dy, x0 + nx * dx, y_top)
    if not crs and looks_like_degrees(bounds, (dx, dy)):
        crs, geographic = ASSUMED_GEOGRAPHIC, True
        meta.update(geographic=True, assumed_crs=(
            f"no CRS in the file; its extent x {bounds[0]:g}..{bounds[2]:g}, y {bounds[1]:g}.."
            f"{bounds[3]:g} in cells of {dx:.4g} looks like degrees: assumed "
            f"{ASSUMED_GEOGRAPHIC} (WGS 84; give a .prj or a CRS in the file if it is not)"))
    out = Raster(data, (x0, y_top - ny * dy), (dx, dy), crs, nodata, Path(path).name,
                 units or "", meta)
    if geographic and project:
        out = to_projected(out, str(path))
        warnings.warn(f"{path}: {out.meta['reprojected']}", UserWarning, stacklevel=2)
    return out


def read_terrain(path, positive: str | None = None, **hints) -> Raster:
    """Any raster of a ``terrain`` row of :mod:`geoshade.io.formats`, by its row's reader
    (GeoTIFF, Arc ASCII, SRTM: :func:`read_dem`; IRAP surfaces:
    :func:`geoshade.io.layers.irap.read_irap`); anything else by :func:`read_dem`, which says
    what it is not. ``positive`` (``"down"``: the values are depths, ``"up"``: heights) is for
    the surfaces that do not state it (IRAP); a raster of heights refuses it in one line.

    >>> import tempfile, os
    >>> f = os.path.join(tempfile.mkdtemp(), "top.fgr")
    >>> _ = open(f, "w").write("-996 2 10 20\\n100 110 200 220\\n2 0 100 200\\n0 0 0 0 0 0 0\\n"
    ...                         "1500 1510 1490 1505\\n")
    >>> float(read_terrain(f).data.max()), float(read_terrain(f, positive="up").data.max())
    (-1490.0, 1510.0)
    """
    fmt = formats.find(path)
    if positive is not None:
        if fmt is None or fmt.name != "irap":
            kind = fmt.title if fmt is not None else "raster"
            raise InputError(f"{path}: --positive (positive=) applies to IRAP surfaces, whose "
                             f"values state no sign; a {kind} holds heights")
        hints["positive"] = positive
    if fmt is not None and fmt.domain == "terrain":
        return fmt.function()(path, **hints)
    return read_dem(path, **hints)


def _by_rasterio(path) -> bool:
    fmt = formats.find(path)
    return fmt is None or fmt.domain != "terrain" or fmt.reader == _READ_DEM


#: the name the format table gives the reader of the rasters rasterio opens
_READ_DEM = "geoshade.io.layers.dem:read_dem"


def _dst_grid(origin, spacing, shape):
    return grid_transform(origin, spacing, shape), (int(shape[1]), int(shape[0]))


def _check_crs(src_crs: str, dst_crs: str, what: str) -> tuple[str, str]:
    """Both CRS, or (``""``, ``""``) when one is unknown (then the coordinates are taken as
    they are, with a warning)."""
    if src_crs and dst_crs:
        return src_crs, dst_crs
    if src_crs != dst_crs:
        warnings.warn(f"{what}: one of the grids has no CRS ({src_crs or 'none'} / "
                      f"{dst_crs or 'none'}); coordinates taken as they are", stacklevel=3)
    return "", ""


def overlap_fraction(bounds, target) -> float:
    """Fraction of the box ``target (xmin, ymin, xmax, ymax)`` inside ``bounds``.

    >>> overlap_fraction((0, 0, 10, 10), (5, 0, 15, 10))
    0.5
    """
    w = min(bounds[2], target[2]) - max(bounds[0], target[0])
    h = min(bounds[3], target[3]) - max(bounds[1], target[1])
    area = (target[2] - target[0]) * (target[3] - target[1])
    return 0.0 if w <= 0 or h <= 0 or area <= 0 else float(w * h / area)


def _bounds_in(bounds, src_crs: str, dst_crs: str):
    if src_crs and dst_crs and src_crs != dst_crs:
        from rasterio.warp import transform_bounds  # type: ignore[import-untyped, unused-ignore]

        try:
            return tuple(transform_bounds(src_crs, dst_crs, *bounds))
        except Exception as exc:
            raise InputError(f"cannot transform {src_crs} to {dst_crs} ({one_line(exc)})") \
                from None
    return tuple(bounds)


def resample(raster: Raster, origin, spacing, shape, crs: str = "", method: str = "auto",
             what: str = "") -> np.ndarray:
    """``raster`` on the grid ``origin (x0, y0), spacing (dx, dy), shape (nx, ny)`` in ``crs``.

    ``method``: ``auto`` (average when the target cells are larger, else bilinear),
    ``bilinear``, ``nearest``, ``average``. Returns ``(ny, nx) float64``, row 0 south, NaN
    where the raster has no data. A raster that misses the grid is an error; one that covers
    part of it warns with the fraction covered.

    Examples
    --------
    >>> r = Raster(np.arange(16.0).reshape(4, 4), (0.0, 0.0), (1.0, 1.0))
    >>> resample(r, (0.0, 0.0), (2.0, 2.0), (2, 2)).tolist()
    [[2.5, 4.5], [10.5, 12.5]]
    """
    _rasterio()
    from rasterio.warp import Resampling, reproject  # type: ignore[import-untyped, unused-ignore]

    what = what or raster.name or "raster"
    src_crs, dst_crs = _check_crs(raster.crs, crs, what)
    target = (origin[0], origin[1], origin[0] + shape[0] * spacing[0],
              origin[1] + shape[1] * spacing[1])
    frac = overlap_fraction(_bounds_in(raster.bounds, src_crs, dst_crs), target)
    if frac <= 0:
        raise InputError(f"{what}: covers x {raster.bounds[0]:g}..{raster.bounds[2]:g}, y "
                         f"{raster.bounds[1]:g}..{raster.bounds[3]:g}{_in(src_crs)}; the model "
                         f"covers x {target[0]:g}..{target[2]:g}, y {target[1]:g}..{target[3]:g}"
                         f"{_in(dst_crs)}: no overlap")
    if frac < 1 - 1e-9:
        warnings.warn(f"{what}: covers {100 * frac:.1f} % of the model's extent; the rest has "
                      "no data", stacklevel=2)
    if method == "auto":
        method = "average" if min(spacing) > 1.5 * max(raster.spacing) else "bilinear"
    try:
        rs = getattr(Resampling, method)
    except AttributeError:
        raise InputError(f"resampling: expected bilinear, nearest or average, got {method!r}") \
            from None
    dst_t, dst_shape = _dst_grid(origin, spacing, shape)
    out = np.full(dst_shape, np.nan, np.float64)
    reproject(np.ascontiguousarray(raster.data[::-1]), out, src_transform=raster.transform(),
              src_crs=src_crs or _LOCAL, src_nodata=np.nan, dst_transform=dst_t,
              dst_crs=dst_crs or _LOCAL, dst_nodata=np.nan, resampling=rs)
    return np.ascontiguousarray(out[::-1])


def _in(crs: str) -> str:
    return f" ({crs})" if crs else ""


def _drape_rgba(arr: np.ndarray, path) -> np.ndarray:
    """(bands, h, w) → (h, w, 4) uint8 with alpha."""
    n = arr.shape[0]
    if n not in (1, 3, 4):
        raise InputError(f"{path}: {n} bands; expected a drape image with 1 (grey), 3 (RGB) or "
                         "4 (RGBA) bands")
    a = np.asarray(arr)
    if a.dtype != np.uint8:
        a = a.astype(np.float64)
        finite = a[np.isfinite(a)]
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        a = np.clip(np.nan_to_num((a - lo) / max(hi - lo, 1e-30) * 255.0), 0, 255)
        a = a.round().astype(np.uint8)
    rgb = np.repeat(a[:1], 3, axis=0) if n == 1 else a[:3]
    alpha = a[3] if n == 4 else np.full(a.shape[1:], 255, np.uint8)
    return np.ascontiguousarray(np.moveaxis(np.concatenate([rgb, alpha[None]]), 0, -1))


def drape_header(path) -> dict:
    """Bounds, CRS, size and bands of a georeferenced drape image, without its pixels (or
    ``{}`` when the file carries no georeference)."""
    with _open(path, "a drape image (RGB GeoTIFF)") as src:
        if src.crs is None and src.transform.is_identity:
            return {}
        t = _checked_transform(src, path)
        return {"bounds": footprint(t, src.width, src.height), "crs": _crs_text(src.crs),
                "size": (src.width, src.height), "bands": src.count}


def drape_for(path, origin, spacing, shape, crs: str = "", check_only: bool = False):
    """A georeferenced drape image on a model's grid (its extent ``origin``, ``spacing``,
    ``shape (nx, ny)``), cropped and resampled (bilinear) to that extent.

    Returns
    -------
    rgba : (h, w, 4) uint8 or None
        Row 0 north, covering exactly the grid's extent; alpha 0 where the image has no data.
        None with ``check_only``.
    covered : float
        Fraction of the grid's extent the image covers (0 < covered <= 1).

    Raises
    ------
    InputError
        No overlap (one line with both extents), not an image, wrong bands.

    Warns
    -----
    UserWarning
        Partial overlap, with the percentage covered.
    """
    _rasterio()
    from rasterio.warp import Resampling, reproject  # type: ignore[import-untyped, unused-ignore]

    with _open(path, "a drape image (RGB GeoTIFF)") as src:
        t = _checked_transform(src, path)   # rotated or not: reproject places it
        if src.count not in (1, 3, 4):
            raise InputError(f"{path}: {src.count} bands; expected a drape image with 1 (grey), "
                             "3 (RGB) or 4 (RGBA) bands")
        src_crs, dst_crs = _check_crs(_crs_text(src.crs), crs, str(path))
        target = (origin[0], origin[1], origin[0] + shape[0] * spacing[0],
                  origin[1] + shape[1] * spacing[1])
        sb = footprint(t, src.width, src.height)
        frac = overlap_fraction(_bounds_in(sb, src_crs, dst_crs), target)
        if frac <= 0:
            raise InputError(f"{path}: the drape covers x {sb[0]:g}..{sb[2]:g}, y {sb[1]:g}.."
                             f"{sb[3]:g}{_in(src_crs)}; the model covers x {target[0]:g}.."
                             f"{target[2]:g}, y {target[1]:g}..{target[3]:g}{_in(dst_crs)}: "
                             "no overlap, nothing to drape")
        if frac < 1 - 1e-9:
            warnings.warn(f"{path}: the drape covers {100 * frac:.1f} % of the model's extent; "
                          "the rest shows the materials' colours", stacklevel=2)
        if check_only:
            return None, frac
        # destination pixels: the source resolution over the model's extent, capped
        res = min(math.hypot(t.a, t.d), math.hypot(t.b, t.e))
        if src_crs and dst_crs and src_crs != dst_crs:
            res = min((target[2] - target[0]) / src.width * 2,
                      (target[3] - target[1]) / src.height * 2)
        w = int(min(MAX_DRAPE_SIDE, max(2, math.ceil((target[2] - target[0]) / res))))
        h = int(min(MAX_DRAPE_SIDE, max(2, math.ceil((target[3] - target[1]) / res))))
        check_memory(w * h * 4 * 3 + src.width * src.height * src.count,
                     path, f"the {w}×{h} drape")
        try:
            arr = src.read()
            mask = src.dataset_mask()
        except Exception as exc:
            raise InputError(f"{path}: cannot read the image ({one_line(exc)})") from None
        rgba = _drape_rgba(arr, path)
        rgba[..., 3] = np.minimum(rgba[..., 3], mask)
        out = np.zeros((4, h, w), np.uint8)
        dst_t = _affine(target[0], target[3], (target[2] - target[0]) / w,
                        (target[3] - target[1]) / h)
        for b in range(4):
            reproject(np.ascontiguousarray(rgba[..., b]), out[b], src_transform=src.transform,
                      src_crs=src_crs or _LOCAL, dst_transform=dst_t, dst_crs=dst_crs or _LOCAL,
                      resampling=Resampling.bilinear, src_nodata=None, dst_nodata=0)
    return np.ascontiguousarray(np.moveaxis(out, 0, -1)), frac


def describe_dem(dem: Raster, stats: bool = True) -> dict:
    """Summary of a DEM for ``geoshade info`` (size, cell size, extent, CRS, nodata, values).

    >>> d = describe_dem(Raster(np.array([[1.0, np.nan]]), (0.0, 0.0), (5.0, 5.0), "EPSG:4326"))
    >>> d["kind"], d["size"], d["nodata_cells"], d["min"], d["max"]
    ('dem', [2, 1], 1, 1.0, 1.0)
    """
    nx, ny = dem.shape
    d = {"kind": "dem", "name": dem.name, "format": _format_name(dem.meta.get("source", "")),
         "source": dem.meta.get("source", ""), "size": [nx, ny], "cells": nx * ny,
         "cell_size": list(dem.spacing), "extent": list(dem.bounds),
         "crs": dem.crs or "(none)", "nodata": dem.nodata, "dtype": dem.meta.get("dtype", ""),
         "unit": dem.unit}
    if dem.meta.get("assumed_crs"):
        d["assumed"] = [dem.meta["assumed_crs"]]
    if dem.meta.get("reprojected"):   # a geographic DEM as geoshade uses it
        d["reprojected"] = dem.meta["reprojected"]
    if dem.meta.get("rotated"):       # a rotated grid as geoshade places it
        d["rotated"] = dem.meta["rotated"]
    d["assumed"] = [*d.get("assumed", []), *dem.meta.get("assumed", [])]
    if not d["assumed"]:
        del d["assumed"]
    if stats:
        ok = np.isfinite(dem.data)
        d["nodata_cells"] = int(ok.size - np.count_nonzero(ok))
        d["min"] = float(np.nanmin(dem.data))
        d["max"] = float(np.nanmax(dem.data))
        d["mean"] = float(np.nanmean(dem.data))
    return d


def _format_name(path) -> str:
    """The title of ``path``'s row of the format table (and "rasterio" where it reads it)."""
    fmt = formats.find(path, sniff=False) if path else None
    if fmt is not None and fmt.reader != _READ_DEM:
        return fmt.title
    return f"{fmt.title if fmt is not None else 'raster'} (rasterio)"


def describe_georeferenced(path) -> dict:
    """``geoshade info`` of a georeferenced TIFF: a DEM (one band) is described with
    :func:`describe_dem`; an image (3 or 4 bands: an orthophoto, a map to drape) by its size,
    bands, extent and CRS. A terrain file rasterio does not read (an IRAP surface) is read by
    its row's reader."""
    if not _by_rasterio(path):
        return describe_dem(read_terrain(path))
    with _open(path, "a GeoTIFF") as src:
        count = src.count
        if count != 1:
            t = src.transform
            b = list(footprint(t, src.width, src.height))
            return {"kind": "georaster", "name": Path(path).name,
                    "format": "GeoTIFF (rasterio)",
                    "source": str(path), "size": [src.width, src.height], "bands": count,
                    "dtype": src.dtypes[0], "cell_size": [abs(t.a), abs(t.e)],
                    "extent": b, "crs": _crs_text(src.crs) or "(none)",
                    "use": "a drape image (stacks render --drape)" if count in (3, 4)
                    else "neither a DEM (1 band) nor a drape (3 or 4 bands)"}
    return describe_dem(read_dem(path))


def format_dem(d: dict) -> str:
    """Text of :func:`describe_dem` (or :func:`describe_georeferenced`) for ``geoshade info``."""
    e = d["extent"]
    if d["kind"] == "georaster":
        return "\n".join([
            f"{d['name']}  (georeferenced image, {d['format']})",
            f"  size     {d['size'][0]} × {d['size'][1]} pixels, {d['bands']} bands "
            f"({d['dtype']})",
            f"  cell     {d['cell_size'][0]:g} × {d['cell_size'][1]:g}",
            f"  extent   x {e[0]:g}..{e[2]:g}, y {e[1]:g}..{e[3]:g}",
            f"  crs      {d['crs']}", f"  use      {d['use']}"])
    lines = [f"{d.get('name') or '(unnamed)'}  (DEM, {d['format']})",
             f"  size     {d['size'][0]} × {d['size'][1]} cells = {d['cells']:,} ({d['dtype']})",
             f"  cell     {d['cell_size'][0]:g} × {d['cell_size'][1]:g}",
             f"  extent   x {e[0]:g}..{e[2]:g}, y {e[1]:g}..{e[3]:g}",
             f"  crs      {d['crs']}",
             f"  nodata   value {d['nodata']}" + (f", {d['nodata_cells']:,} cells"
                                                   if "nodata_cells" in d else "")]
    if "min" in d:
        unit = f" {d['unit']}" if d.get("unit") else ""
        lines.append(f"  heights  min {d['min']:.6g}, max {d['max']:.6g}, mean "
                     f"{d['mean']:.6g}{unit}")
    if d.get("rotated"):
        lines.append(f"  rotated  {d['rotated']}")
    note = d.get("reprojected") or ""
    for a in d.get("assumed", []):
        lines.append(f"  assumed  {a}")
        note = note.replace(f"{a}; ", "")   # said on the line above
    if note:
        lines.append(f"  note     {note}")
    if d.get("source"):
        lines.append(f"  source   {d['source']}")
    return "\n".join(lines)


__all__ = ["Raster", "describe_dem", "describe_georeferenced", "drape_for", "drape_header",
           "footprint", "format_dem", "grid_transform", "is_dem", "is_georeferenced",
           "is_rotated", "looks_like_degrees", "overlap_fraction", "read_dem", "read_terrain",
           "resample", "to_projected", "unrotate", "utm_crs"]
