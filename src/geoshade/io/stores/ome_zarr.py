"""OME-Zarr (OME-NGFF) multiscale metadata: what geoshade's stores say, and what others' say.

geoshade's ingest writes zarr v3 stores, so it writes NGFF **0.5** metadata: the group's
attributes hold ``"ome": {"version": "0.5", "multiscales": [...]}`` (axes ``z, y, x`` of type
``space`` with the volume's unit as an NGFF unit name; per level a ``scale`` and a
``translation``), beside geoshade's own attributes (``spacing``, ``origin``, ``unit``,
``value_range``, ``ingest``), which geoshade reads first.  Stores written by others are read
from that metadata: NGFF 0.5 (zarr v3, under ``"ome"``) and 0.4 and older (``multiscales`` at the
top of the attributes, zarr v2); geoshade stores written before NGFF 0.5 (a 0.4-style
``multiscales`` in a zarr v3 group) still read.

Coordinates follow NGFF's voxel-centre convention (napari and neuroglancer use it too): a level's
``translation`` is the position of the *centre* of its first voxel, while geoshade's ``origin``
is the *corner* of the first voxel, so ``origin = translation - scale / 2`` (per axis).

Axes other than ``z, y, x`` (time ``t``, channel ``c``) must have one element; a store with
several channels or time points is refused with one line saying so (geoshade reads one scalar
volume).
"""

from __future__ import annotations

from dataclasses import dataclass

from geoshade.errors import InputError
from geoshade.io.paths import one_line
from geoshade.io.stores.chunks import DamagedStoreError

#: NGFF version geoshade writes (it writes zarr v3 stores; NGFF 0.4 goes with zarr v2)
NGFF_VERSION = "0.5"

#: geoshade's short length units -> NGFF (UDUNITS-2) unit names
NGFF_UNITS = {
    "um": "micrometer", "µm": "micrometer", "micron": "micrometer", "mm": "millimeter",
    "nm": "nanometer", "cm": "centimeter", "dm": "decimeter", "m": "meter", "km": "kilometer",
    "pm": "picometer", "A": "angstrom", "Å": "angstrom", "ft": "foot", "in": "inch",
    "yd": "yard", "mi": "mile",
}
#: NGFF unit names -> geoshade's short units (the inverse of :data:`NGFF_UNITS`)
SHORT_UNITS = {
    "micrometer": "um", "millimeter": "mm", "nanometer": "nm", "centimeter": "cm",
    "decimeter": "dm", "meter": "m", "kilometer": "km", "picometer": "pm", "angstrom": "A",
    "foot": "ft", "inch": "in", "yard": "yd", "mile": "mi",
}


def ngff_unit(unit: str | None) -> str | None:
    """The NGFF name of a length unit (None: no unit, or one NGFF does not name).

    Examples
    --------
    >>> ngff_unit("um"), ngff_unit("millimeter"), ngff_unit(""), ngff_unit("voxel")
    ('micrometer', 'millimeter', None, None)
    """
    if not unit:
        return None
    u = str(unit).strip()
    if u in SHORT_UNITS:
        return u
    return NGFF_UNITS.get(u) or NGFF_UNITS.get(u.lower())


def short_unit(unit: str | None) -> str:
    """geoshade's short form of an NGFF unit name (other strings unchanged).

    Examples
    --------
    >>> short_unit("micrometer"), short_unit("meter"), short_unit("parsec"), short_unit(None)
    ('um', 'm', 'parsec', '')
    """
    if not unit:
        return ""
    return SHORT_UNITS.get(str(unit), str(unit))


def multiscales_attrs(name: str, shapes, spacing, origin, unit: str | None,
                      method: str = "nearest", version: str = NGFF_VERSION) -> dict:
    """The group attributes that make a geoshade pyramid an OME-Zarr multiscale image.

    Parameters
    ----------
    name : str
        The image's name.
    shapes : list of (nz, ny, nx)
        The levels, level 0 first, stored at paths ``"0"``, ``"1"``, ...; level k halves
        level k - 1 (``geoshade.io.stores.ingest.level_shapes``), so its voxel is ``2**k`` level-0 voxels.
    spacing, origin : (x, y, z)
        Level 0's voxel size and the corner of its first voxel.
    unit : str
        Length unit (``um``, ``mm`` ...); omitted from the axes when NGFF has no name for it.
    method : {"nearest", "mean"}
        How the levels were made: a ``nearest`` level-k voxel is level-0 voxel ``2**k * i``
        (its centre is the level-0 voxel's centre); a ``mean`` one is the centre of its block.
    version : {"0.5", "0.4"}
        ``0.5`` for zarr v3 stores (under ``"ome"``), ``0.4`` for zarr v2 stores.

    Returns
    -------
    dict
        ``{"ome": {"version": "0.5", "multiscales": [...]}}`` or, for 0.4,
        ``{"multiscales": [{"version": "0.4", ...}]}``.

    Examples
    --------
    >>> a = multiscales_attrs("core", [(4, 4, 4), (2, 2, 2)], (0.5, 0.5, 1.0), (0, 0, 0), "um")
    >>> ms = a["ome"]["multiscales"][0]
    >>> ms["axes"][0], ms["datasets"][1]["coordinateTransformations"]
    ({'name': 'z', 'type': 'space', 'unit': 'micrometer'}, [{'type': 'scale', 'scale': [2.0, 1.0, 1.0]}, {'type': 'translation', 'translation': [0.5, 0.25, 0.25]}])
    """  # noqa: E501
    if version not in ("0.4", "0.5"):
        raise InputError(f"version: expected NGFF '0.4' or '0.5', got {version!r}")
    u = ngff_unit(unit)
    axes = [{"name": a, "type": "space", **({"unit": u} if u else {})} for a in "zyx"]
    sp = [float(spacing[2]), float(spacing[1]), float(spacing[0])]
    og = [float(origin[2]), float(origin[1]), float(origin[0])]
    datasets = []
    for k in range(len(shapes)):
        f = 2**k
        c = 0.5 * (f if method == "mean" else 1)  # the level-k voxel centre, in level-0 voxels
        datasets.append({"path": str(k), "coordinateTransformations": [
            {"type": "scale", "scale": [s * f for s in sp]},
            {"type": "translation", "translation": [o + c * s for o, s in zip(og, sp,
                                                                              strict=True)]}]})
    ms = {"name": str(name), "axes": axes, "datasets": datasets, "type": str(method)}
    if version == "0.4":
        return {"multiscales": [{"version": "0.4", **ms}]}
    return {"ome": {"version": "0.5", "multiscales": [ms]}}


@dataclass(frozen=True)
class Multiscale:
    """The first image of a group's ``multiscales`` metadata, checked.

    version:      str or None                NGFF version the metadata declare
    axes:         list of str                axis names in array order (``z, y, x`` among them)
    paths:        list of str                array path of each level, level 0 first
    scales:       list of (sx, sy, sz)|None  each level's voxel size (None: not given)
    translations: list of (x, y, z)|None     each level's first voxel centre (None: not given)
    unit:         str                        geoshade's short unit ('' if none or mixed)
    """

    version: str | None
    axes: list[str]
    paths: list[str]
    scales: list[tuple[float, float, float] | None]
    translations: list[tuple[float, float, float] | None]
    unit: str

    @property
    def space_index(self) -> tuple[int, int, int]:
        """Positions of the z, y, x axes in the arrays' dimensions."""
        return (self.axes.index("z"), self.axes.index("y"), self.axes.index("x"))

    def spacing(self, level: int = 0) -> tuple[float, float, float] | None:
        """Voxel size (x, y, z) of ``level`` (None: no scale given)."""
        return self.scales[level]

    def origin(self, level: int = 0) -> tuple[float, float, float] | None:
        """Corner (x, y, z) of ``level``'s first voxel: its centre minus half a voxel."""
        t, s = self.translations[level], self.scales[level]
        if t is None and s is None:
            return None
        t, s = t or (0.0, 0.0, 0.0), s or (1.0, 1.0, 1.0)
        return (t[0] - s[0] / 2, t[1] - s[1] / 2, t[2] - s[2] / 2)

    def index(self, shape, path, level: int = 0) -> tuple:
        """The index that turns an array of ``shape`` into a ``(nz, ny, nx)`` view: 0 for the
        single element of each non-space axis; one line if an axis has several."""
        shape = tuple(int(n) for n in shape)
        if len(shape) != len(self.axes):
            raise DamagedStoreError(
                f"{path}: array {self.paths[level]}: has {len(shape)} dimensions but the "
                f"'multiscales' metadata name {len(self.axes)} axes ({', '.join(self.axes)})")
        idx: list = []
        for name, n in zip(self.axes, shape, strict=True):
            if name in ("z", "y", "x"):
                idx.append(slice(None))
            elif n == 1:
                idx.append(0)
            else:
                what = {"c": "channels", "t": "time points"}.get(name, f"elements along {name!r}")
                raise InputError(
                    f"{path}: OME-Zarr image with {n} {what} (axes {', '.join(self.axes)}, "
                    f"shape {shape}); geoshade reads one scalar 3D volume (z, y, x): write "
                    f"one {'channel' if name == 'c' else 'element'} to its own store")
        zyx = [self.axes.index(a) for a in "zyx"]
        if zyx != sorted(zyx):
            raise InputError(f"{path}: OME-Zarr axes {', '.join(self.axes)}: expected z, y, x "
                             "in that order (NGFF requires it)")
        return tuple(idx)


def find_multiscales(attrs: dict):
    """The raw ``multiscales`` list of a group's attributes (NGFF 0.5 under ``"ome"``, older at
    the top), or None."""
    ome = attrs.get("ome")
    if isinstance(ome, dict) and ome.get("multiscales") is not None:
        return ome["multiscales"]
    return attrs.get("multiscales") or None


def _transforms(node: dict, n: int, what: str) -> tuple[list | None, list | None]:
    """(scale, translation) of a node's ``coordinateTransformations`` (None where absent)."""
    s = t = None
    for tr in node.get("coordinateTransformations") or []:
        if tr["type"] == "scale":
            s = [float(v) for v in tr["scale"]]
        elif tr["type"] == "translation":
            t = [float(v) for v in tr["translation"]]
    for v, name in ((s, "scale"), (t, "translation")):
        if v is not None and len(v) != n:
            raise ValueError(f"{name} of {what}: expected {n} numbers (one per axis), got {v!r}")
    return s, t


def _vec(values, idx, what: str) -> tuple[float, float, float]:
    vals = [float(values[i]) for i in idx]  # z, y, x positions -> x, y, z below
    if any(v != v or v in (float("inf"), float("-inf")) for v in vals):
        raise ValueError(f"{what}: expected finite numbers, got {values!r}")
    return (vals[2], vals[1], vals[0])


def parse_multiscales(attrs: dict, path) -> Multiscale | None:
    """The first multiscale image of a group's attributes, checked (None: no ``multiscales``).

    Raises
    ------
    DamagedStoreError
        The metadata are not what NGFF describes (one line naming the attribute).
    InputError
        Valid metadata of an image geoshade cannot read as a volume (no z, y, x axes).

    Examples
    --------
    >>> a = multiscales_attrs("v", [(2, 2, 2)], (0.5, 0.5, 2.0), (10, 0, 0), "mm")
    >>> m = parse_multiscales(a, "v.zarr")
    >>> m.paths, m.spacing(0), m.origin(0), m.unit
    (['0'], (0.5, 0.5, 2.0), (10.0, 0.0, 0.0), 'mm')
    >>> parse_multiscales({"ome": {"version": "0.5", "multiscales": [{"datasets": 5}]}}, "v")
    Traceback (most recent call last):
    ...
    geoshade.io.stores.chunks.DamagedStoreError: v: zarr.json: damaged 'multiscales' attribute ...
    """
    raw = find_multiscales(attrs)
    if raw is None:
        return None
    ome_raw = attrs.get("ome")
    ome: dict = ome_raw if isinstance(ome_raw, dict) else {}
    try:
        ms0 = raw[0]
        datasets = ms0["datasets"]
        paths = [str(d["path"]) for d in datasets]
        if not paths:
            raise ValueError("datasets: expected at least one level")
        axes_raw = ms0.get("axes")
        if axes_raw is None:  # NGFF 0.1-0.3: 5D t, c, z, y, x
            axes_raw = ["t", "c", "z", "y", "x"]
        axes = [str(a["name"]) if isinstance(a, dict) else str(a) for a in axes_raw]
        version = ome.get("version") or ms0.get("version")
        units = {a.get("unit") for a in axes_raw if isinstance(a, dict)
                 and a.get("name") in ("z", "y", "x")}
        gs, gt = _transforms(ms0, len(axes), "the image")  # apply to every level, after its own
        scales: list = []
        trans: list = []
        for d in datasets:
            s, t = _transforms(d, len(axes), f"level {d['path']}")
            if gs is not None:
                t = None if t is None and gt is None else [
                    a * b for a, b in zip(t or [0.0] * len(axes), gs, strict=True)]
                s = [a * b for a, b in zip(s or [1.0] * len(axes), gs, strict=True)]
            if gt is not None:
                t = [a + b for a, b in zip(t or [0.0] * len(axes), gt, strict=True)]
            scales.append(s)
            trans.append(t)
    except (AttributeError, IndexError, KeyError, TypeError, ValueError) as err:
        raise DamagedStoreError(f"{path}: zarr.json: damaged 'multiscales' attribute "
                                f"({one_line(err)})") from None
    missing = [a for a in "zyx" if a not in axes]
    if missing:
        raise InputError(f"{path}: OME-Zarr image with axes {', '.join(axes) or 'none'}; "
                         f"geoshade reads 3D volumes: expected axes z, y, x (missing "
                         f"{', '.join(missing)})")
    idx = [axes.index(a) for a in "zyx"]
    try:
        sp = [None if s is None else _vec(s, idx, "scale") for s in scales]
        tr = [None if t is None else _vec(t, idx, "translation") for t in trans]
    except (TypeError, ValueError) as err:
        raise DamagedStoreError(f"{path}: zarr.json: damaged 'multiscales' attribute "
                                f"({one_line(err)})") from None
    bad = [s for s in sp if s is not None and min(s) <= 0]
    if bad:
        raise DamagedStoreError(f"{path}: zarr.json: damaged 'multiscales' attribute (scale: "
                                f"expected positive numbers, got {bad[0]})")
    unit = short_unit(units.pop()) if len(units) == 1 and None not in units else ""
    return Multiscale(version=None if version is None else str(version), axes=axes, paths=paths,
                      scales=sp, translations=tr, unit=unit)


__all__ = ["NGFF_UNITS", "NGFF_VERSION", "SHORT_UNITS", "Multiscale", "find_multiscales",
           "multiscales_attrs", "ngff_unit", "parse_multiscales", "short_unit"]
