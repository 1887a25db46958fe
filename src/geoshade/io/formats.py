"""The one table of the kinds of file geoshade reads: one :class:`Format` row each.

A row says everything the rest of geoshade needs about a kind of file: its name, how a path is
recognised (suffixes, a suffix pattern such as ``.X0001``, the files that make a folder one), its
domain, its reader **by name** (imported only when a file of that kind is read), the ``ingest``
command that takes it, the optional extra it needs, and the files of a case that travel with it.
:func:`geoshade.io.load`, ``geoshade info``, ``core ingest``/``grid ingest``, the browser's file
list (:mod:`geoshade.web.catalog`) and the output guard (:func:`case_files`) all read this table,
so that a new format is one row here and one reader in its module::

    Format("srtm", "SRTM height tile", "terrain", "geoshade.io.layers.dem:read_dem",
           suffixes=(".hgt", ".hgt.zip"), extra="geo")

Importing this module imports no reader and no reader package.

>>> format_of("scan.tif").title, format_of("CASE.X0012").name, format_of("a.stacks.npz").name
('TIFF stack', 'eclipse', 'stacks')
>>> format_of("N46E008.hgt.zip").domain, format_of("dem.asc").extra
('terrain', 'geo')
"""

from __future__ import annotations

import fnmatch
import importlib
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from geoshade.errors import InputError, require

#: what a format holds: ``volume`` (voxels: the core), ``grid`` (corner-point grids), ``layers``
#: (label volumes and stack models: stacks), ``field`` (values over time: iso), ``terrain``
#: (rasters of heights placed on the ground: stacks terrain models), ``summary`` (vectors over
#: time of a simulation run: ``geoshade summary``)
DOMAINS = ("volume", "grid", "layers", "field", "terrain", "summary")
#: the ingest commands: ``core`` (``geoshade core ingest``: a chunked multiscale volume store),
#: ``grid`` (``geoshade grid ingest``: a chunked grid store)
INGEST = {"core": "geoshade core ingest", "grid": "geoshade grid ingest"}
#: the package each optional extra installs that a reader needs
EXTRA_PACKAGES = {"roff": "roffio", "netcdf": "netCDF4", "hdf5": "h5py", "geo": "rasterio",
                  "nrrd": "nrrd"}

Reader = Callable[..., Any]


@dataclass(frozen=True)
class Format:
    """One kind of file geoshade reads.

    name:      str             short identifier (``tiff``, ``eclipse``, ``srtm``)
    title:     str             what users call it, for messages (``TIFF stack``)
    domain:    str             one of :data:`DOMAINS`
    reader:    str | callable  ``"module:function"`` (imported when used) or the function;
                               ``reader(path, **hints) -> model``
    suffixes:  tuple of str    lower-case endings of the name, possibly double (``.hgt.zip``)
    patterns:  tuple of str    regular expressions a name's last suffix must match, in any
                               case (``\\.[XF]\\d{4}``: a report number in the suffix)
    folder:    tuple of str    ``fnmatch`` patterns of entries of which one makes a folder this
                               kind (``zarr.json``, ``*.tif``); hidden entries only match a
                               pattern that starts with a dot
    test:      str or None     ``"module:function(path) -> bool"`` telling this kind from a later
                               row with the same suffixes (a GeoTIFF DEM among TIFF stacks)
    ingest:    str or None     the key in :data:`INGEST` of the command that ingests it
    source:    str or None     ``"module:Class"`` that streams it into a grid store
                               (``Class(path, progress=None)``, slab by slab; None: read
                               whole by ``reader``, then written)
    extra:     str or None     the optional extra the reader needs (:data:`EXTRA_PACKAGES`)
    case:      tuple of str    the files that travel with one: glob patterns beside it with
                               ``{stem}`` (the name without its suffix) and ``{name}``, or
                               ``"module:function(path) -> paths"`` (a header's data file)
    hints:     str             what the user must or may add, for messages
    header:    str or None     ``"module:function(path, **hints) -> Header"``: what a file
                               declares (shape, dtype, cells, a store's levels) read without
                               its arrays, for the memory plan (:mod:`geoshade.io.plan`);
                               None: nothing is known before loading
    """

    name: str
    title: str
    domain: str
    reader: str | Reader
    suffixes: tuple[str, ...] = ()
    patterns: tuple[str, ...] = ()
    folder: tuple[str, ...] = ()
    test: str | None = None
    ingest: str | None = None
    source: str | None = None
    extra: str | None = None
    case: tuple[str, ...] = ()
    hints: str = ""
    header: str | None = None

    def __post_init__(self):
        if self.domain not in DOMAINS:
            raise ValueError(f"format {self.name}: domain {self.domain!r}; expected one of "
                             f"{', '.join(DOMAINS)}")
        if self.ingest is not None and self.ingest not in INGEST:
            raise ValueError(f"format {self.name}: ingest {self.ingest!r}; expected one of "
                             f"{', '.join(INGEST)}")
        if self.extra is not None and self.extra not in EXTRA_PACKAGES:
            raise ValueError(f"format {self.name}: extra {self.extra!r}; expected one of "
                             f"{', '.join(EXTRA_PACKAGES)}")
        object.__setattr__(self, "suffixes", tuple(
            s.lower() if s.startswith(".") else "." + s.lower() for s in self.suffixes))

    def named(self, path) -> bool:
        """Whether the *name* of ``path`` is of this kind (its suffix or pattern; no file is
        opened, folders are not looked into).

        >>> FORMATS[0].named("scan.RAW"), FORMATS[0].named("scan.raw.nhdr")
        (True, False)
        """
        p = Path(path)
        name = p.name.lower()
        if any(name.endswith(s) and len(name) > len(s) for s in self.suffixes):
            return True
        return any(re.fullmatch(pat, p.suffix, re.IGNORECASE) for pat in self.patterns)

    def holds(self, folder: Path) -> bool:
        """Whether ``folder`` (a folder without a known suffix) is of this kind."""
        if not self.folder:
            return False
        try:
            names = [e.name for e in folder.iterdir()]
        except OSError:
            return False
        for n in names:
            low = n.lower()
            for pat in self.folder:
                if (not n.startswith(".") or pat.startswith(".")) and fnmatch.fnmatchcase(
                        low, pat.lower()):
                    return True
        return False

    def function(self) -> Reader:
        """The reader, imported now; a missing extra is one line naming ``pip install``."""
        if self.extra is not None:
            require(EXTRA_PACKAGES[self.extra], self.extra, f"reading {self.title}")
        return resolve(self.reader)

    def companions(self, path) -> list[Path]:
        """The files beside ``path`` that belong with it (see ``case``), ``path`` excluded."""
        p = Path(path)
        if not self.case or not p.parent.is_dir():
            return []
        stem = _stem(p, self)
        out: list[Path] = []
        for c in self.case:
            if ":" in c:
                found = resolve(c)(p)
                out += [Path(f) for f in ([found] if isinstance(found, str | Path) else
                                          found or [])]
            else:
                pat = c.format(stem=_glob_escape(stem), name=_glob_escape(p.name))
                out += sorted(p.parent.glob(pat))
        return [q for q in dict.fromkeys(out) if q != p and q.is_file()]


def _stem(p: Path, fmt: Format) -> str:
    """``p``'s name without the suffix that made it ``fmt`` (``N46E008.hgt.zip`` → ``N46E008``)."""
    name = p.name
    for s in sorted(fmt.suffixes, key=len, reverse=True):
        if name.lower().endswith(s):
            return name[: -len(s)]
    return name[: -len(p.suffix)] if p.suffix else name


def _glob_escape(text: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", text)


def resolve(name: str | Reader) -> Reader:
    """The function ``"module:function"`` names, imported now (a callable is returned as is).

    >>> resolve("os.path:join")("a", "b")
    'a/b'
    """
    if callable(name):
        return name
    module, _, attr = str(name).partition(":")
    return getattr(importlib.import_module(module), attr)


_TIFF = (".tif", ".tiff")
_GRDECL_STREAM = "geoshade.io.grids.grdecl_stream:GrdeclSource"

#: every kind of file :func:`geoshade.io.load` reads, tried in this order: the first row whose
#: name (and ``test``, where it has one) matches is the file's kind
FORMATS: list[Format] = [
    Format("raw", "headerless raw volume", "volume", "geoshade.io.volumes.sidecar:read_raw_hinted",
           (".raw", ".bin", ".img", ".vol", ".dat"), ingest="core",
           case=("{stem}.nhdr", "{stem}.mhd", "{name}.nhdr", "{name}.mhd"),
           hints="--dtype, and --shape unless a cube or a .nhdr/.mhd beside it",
           header="geoshade.io.volumes.headers:raw_header"),
    Format("nrrd", "NRRD volume", "volume", "geoshade.io.volumes.sidecar:read_nhdr",
           (".nhdr", ".nrrd"), ingest="core", extra="nrrd",
           case=("geoshade.io.volumes.sidecar:data_file_of",),
           hints=".nhdr header + raw file, or .nrrd",
           header="geoshade.io.volumes.headers:nrrd_header"),
    Format("metaimage", "MetaImage volume", "volume", "geoshade.io.volumes.sidecar:read_mhd",
           (".mhd", ".mha"), ingest="core", case=("geoshade.io.volumes.sidecar:data_file_of",),
           hints=".mhd header + raw file, or .mha",
           header="geoshade.io.volumes.headers:mhd_header"),
    Format("geotiff", "GeoTIFF", "terrain", "geoshade.io.layers.dem:read_dem", _TIFF,
           test="geoshade.io.layers.dem:is_dem", extra="geo",
           case=("{stem}.tfw", "{name}.aux.xml"), hints="a DEM: one georeferenced band"),
    Format("tiff", "TIFF stack", "volume", "geoshade.io.volumes.tiff:read_tiff", _TIFF,
           ingest="core", header="geoshade.io.volumes.headers:tiff_header"),
    Format("tiff-folder", "folder of TIFF slices", "volume",
           "geoshade.io.volumes.tiff:read_tiff_folder", folder=("*.tif", "*.tiff"),
           ingest="core", header="geoshade.io.volumes.headers:tiff_folder_header"),
    Format("stacks", "geoshade stack model", "layers", "geoshade.io.layers.stackfile:read_stacks",
           (".stacks.npz",), header="geoshade.io.layers.headers:stacks_header"),
    Format("numpy", "NumPy array", "volume", "geoshade.io.volumes.npy:read_npy",
           (".npy", ".npz"), ingest="core", hints="a 4D .npy is a field over time",
           header="geoshade.io.volumes.headers:npy_header"),
    Format("zarr", "zarr store", "volume", "geoshade.io.stores.grid_store:read_store",
           (".zarr",), folder=("zarr.json", ".zarray", ".zgroup"), ingest="core",
           hints="a volume, or a grid store of 'geoshade grid ingest'",
           header="geoshade.io.stores.headers:zarr_header"),
    Format("geotop", "GeoTOP netCDF", "layers", "geoshade.io.layers.geotop:read_geotop",
           (".nc",), test="geoshade.io.layers.layer_model:is_voxel_model", extra="netcdf",
           hints="variable=lithok|strat", header="geoshade.io.layers.headers:netcdf_header"),
    Format("layer-model", "layer model (top/bottom per layer)", "layers",
           "geoshade.io.layers.layer_model:read_layer_model", (".nc4", ".nc", ".cdf", ".netcdf"),
           extra="netcdf", hints="top + bottom/botm variables (layer, y, x)"),
    Format("hdf5", "HDF5 dataset", "volume", "geoshade.io.volumes.hdf5:read_hdf5",
           (".h5", ".hdf5", ".hdf", ".he5"), ingest="core", extra="hdf5",
           hints="dataset=PATH if several", header="geoshade.io.volumes.headers:hdf5_header"),
    Format("eclipse-grid", "ECLIPSE GRID file (old, binary or formatted)", "grid",
           "geoshade.io.grids.ecl:load_case", (".grid", ".fgrid"),
           test="geoshade.io.grids.ecl_gridfile:is_ecl_grid", case=("{stem}.*",),
           hints="told from GRDECL text by its content; an INIT and restarts beside it are read"),
    Format("grdecl", "GRDECL corner-point grid", "grid", "geoshade.io.grids.grdecl:read_grdecl",
           (".grdecl", ".grid", ".inc"), ingest="grid", source=_GRDECL_STREAM,
           case=("{stem}.*",), header="geoshade.io.grids.headers:grdecl_header"),
    Format("summary", "ECLIPSE/OPM summary", "summary", "geoshade.io.grids.summary:read_summary",
           (".smspec", ".fsmspec", ".unsmry", ".funsmry"),
           test="geoshade.io.grids.summary:summary_alone", case=("{stem}.*",),
           hints="vectors over time; with a grid beside it the case's grid, "
                 "load(..., as_='summary') the vectors of any file of the case"),
    Format("eclipse", "ECLIPSE/OPM case", "grid", "geoshade.io.grids.ecl:load_case",
           (".egrid", ".fegrid", ".init", ".finit", ".unrst", ".funrst", ".smspec", ".unsmry",
            ".fsmspec", ".funsmry"), patterns=(r"\.[XF]\d{4}",), ingest="grid",
           source="geoshade.io.stores.ecl_source:EclSource", case=("{stem}.*",),
           header="geoshade.io.grids.headers:egrid_header",
           hints="any of its files, binary or formatted (EGRID + INIT, restarts beside it)"),
    Format("roff", "ROFF grid (RMS)", "grid", "geoshade.io.grids.roff:read_roff",
           (".roff", ".roffasc", ".roffbin"), ingest="grid", extra="roff",
           case=("{stem}--*.roff", "{stem}--*.roffasc", "{stem}--*.roffbin"),
           hints="properties=[parameter files] or NAME--PROP.roff beside it"),
    Format("deck", "ECLIPSE/OPM input deck", "grid", "geoshade.io.grids.deck:read_deck",
           (".data",), ingest="grid", source=_GRDECL_STREAM, case=("{stem}.*",),
           header="geoshade.io.grids.headers:grdecl_header"),
    Format("arc-ascii", "Arc ASCII grid", "terrain", "geoshade.io.layers.dem:read_dem",
           (".asc",), extra="geo", case=("{stem}.prj", "{name}.aux.xml"),
           hints="the CRS from a .prj beside it"),
    Format("srtm", "SRTM height tile", "terrain", "geoshade.io.layers.dem:read_dem",
           (".hgt", ".hgt.zip"), extra="geo", hints="N46E008.hgt: its name places it"),
    Format("irap", "IRAP surface (RMS)", "terrain", "geoshade.io.layers.irap:read_irap",
           (".gri", ".irap", ".irapbin", ".fgr", ".irapasc"), extra="geo",
           hints="classic ASCII or binary, told by content; values taken as depth"),
]


def register(fmt: Format) -> None:
    """Add a row (before every row, so that it wins over a built-in one of the same suffix).

    >>> register(Format("myvol", "my volume", "volume", "geoshade.io.volumes.npy:read_npy",
    ...                 (".myvol",)))
    >>> format_of("x.myvol").title
    'my volume'
    >>> unregister("myvol")
    """
    unregister(fmt.name)
    FORMATS.insert(0, fmt)


def unregister(name: str) -> None:
    """Remove the row named ``name`` (none: nothing happens)."""
    FORMATS[:] = [f for f in FORMATS if f.name != name]


def register_reader(suffixes: Iterable[str], reader: str | Reader, description: str,
                    domain: str = "volume") -> Format:
    """Compatibility: make :func:`geoshade.io.load` read files ending in ``suffixes`` with
    ``reader`` (one row named after the first suffix); returns the row."""
    sufs = tuple(suffixes)
    fmt = Format(sufs[0].lstrip(".").lower(), description, domain, reader, sufs)
    register(fmt)
    return fmt


def find(path, sniff: bool = True) -> Format | None:
    """The row of ``path`` (None: no kind of file geoshade reads).

    ``sniff=False`` decides by the name alone (no file is opened; a row with a ``test`` is
    taken when its name matches, so a ``.tif`` is a GeoTIFF DEM), as a file list does.
    """
    p = Path(path)
    named = [f for f in FORMATS if f.named(p)]
    for f in named:
        if not sniff or f.test is None or p.is_dir() or _passes(f, p):
            return f
    if named:
        return named[-1]
    if p.is_dir():
        return next((f for f in FORMATS if f.holds(p)), None)
    return None


def _passes(fmt: Format, p: Path) -> bool:
    try:
        return bool(resolve(fmt.test)(p)) if fmt.test else True
    except Exception:  # the test of an optional kind failed: the later row's reader says why
        return False


def format_of(path) -> Format:
    """The row of ``path``, else one line listing what geoshade reads."""
    fmt = find(path)
    if fmt is not None:
        return fmt
    p = Path(path)
    if p.is_dir():
        raise InputError(f"{path}: folder is not a known volume; expected one of: {text()}")
    raise InputError(f"{path}: unknown file type {p.suffix or '(no suffix)'!r}; expected one "
                     f"of: {text()}")


def text(formats: Iterable[Format] | None = None) -> str:
    """One line naming every kind of file (with its suffixes) for messages and ``--help``."""
    parts = []
    for f in FORMATS if formats is None else formats:
        names = "/".join(f.suffixes) + ("/" if f.suffixes and f.patterns else "") + "/".join(
            p.replace("\\.", ".").replace("\\d{4}", "0001").replace("[XF]", "X") for p in
            f.patterns)
        where = names or ("folder of " + ", ".join(f.folder))
        extra = f", the {f.extra} extra" if f.extra else ""
        hints = f": {f.hints}" if f.hints else ""
        parts.append(f"{where} ({f.title}{hints}{extra})")
    return "; ".join(parts)


def listed(path) -> bool:
    """Whether a file list shows ``path``: a file whose name is of a kind geoshade reads, or a
    folder of one (a zarr store, a folder of TIFF slices); nothing is opened but folders.

    >>> listed("a.EGRID"), listed("a.X0003"), listed("notes.txt"), listed("N46E008.hgt.zip")
    (True, True, False, True)
    """
    p = Path(path)
    if any(f.named(p) for f in FORMATS):
        return True
    return p.is_dir() and any(f.holds(p) for f in FORMATS)


def ingested_by(path, command: str) -> Format:
    """The row of ``path`` when the ingest ``command`` (a key of :data:`INGEST`) takes it, else
    one line saying which command does, or what this one takes.

    >>> ingested_by("scan.tif", "core").name
    'tiff'
    >>> try:
    ...     ingested_by("CASE.EGRID", "core")
    ... except InputError as e:
    ...     print(e)
    CASE.EGRID: an ECLIPSE/OPM case is ingested by geoshade grid ingest, not geoshade core ingest
    """
    fmt = format_of(path)
    if fmt.ingest == command:
        return fmt
    if fmt.ingest is not None:
        raise InputError(f"{path}: an {fmt.title} is ingested by {INGEST[fmt.ingest]}, not "
                         f"{INGEST[command]}")
    takes = ", ".join(dict.fromkeys(f.title for f in FORMATS if f.ingest == command))
    raise InputError(f"{path}: {INGEST[command]} does not take a {fmt.title}; it takes: {takes}")


def suffixes(domain: str | None = None) -> tuple[str, ...]:
    """Every suffix of the rows (of one ``domain``), in table order, each once."""
    out: dict[str, None] = {}
    for f in FORMATS:
        if domain is None or f.domain == domain:
            out.update(dict.fromkeys(f.suffixes))
    return tuple(out)


def case_files(*paths) -> list[Path]:
    """The files a command reads when it is given ``paths``: each path and the files of its case
    beside it (an ECLIPSE case's EGRID, INIT, UNRST, X0001, SMSPEC ...; a raw file's
    ``.nhdr``/``.mhd`` header; a header's data file; ROFF ``NAME--PROP.roff``; an Arc ASCII
    grid's ``.prj``). None entries are skipped. An output must name none of them.

    >>> import os, tempfile
    >>> d = tempfile.mkdtemp()
    >>> for n in ("C.EGRID", "C.INIT", "C.X0001", "other.INIT"):
    ...     open(os.path.join(d, n), "wb").close()
    >>> [p.name for p in case_files(os.path.join(d, "C.EGRID"))]
    ['C.EGRID', 'C.INIT', 'C.X0001']
    """
    out: list[Path] = []
    for path in paths:
        if path is None:
            continue
        p = Path(path)
        out.append(p)
        fmt = find(p, sniff=False)
        if fmt is not None and not p.is_dir():
            out += fmt.companions(p)
    return list(dict.fromkeys(out))


__all__ = ["DOMAINS", "EXTRA_PACKAGES", "FORMATS", "INGEST", "Format", "case_files", "find",
           "format_of", "ingested_by", "listed", "register", "register_reader", "resolve",
           "suffixes", "text", "unregister"]
