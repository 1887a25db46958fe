"""Another quantity of the same file as the isosurface: the live ``keyword`` change.

``view.update(keyword="PRESSURE")`` (the viewers' keyword control) shows another quantity of
the case or file the field came from, as opening with it does: a corner-point grid's field is
made again by :func:`geoshade.iso.api.field_of`, an ECLIPSE case or a netCDF/zarr/npz file read
again by :func:`geoshade.io.fields.load_field` (its ``keyword``), and a field given as arrays
takes one of its own ``properties``. What belongs to the old quantity is reset unless given in
the same change: the level (assumed again), the step (the new field's default), the change
``diff`` and a colour quantity the new field lacks.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from geoshade.errors import InputError
from geoshade.io.fields import load_field
from geoshade.iso.api import field_of, refined_hosts_hidden
from geoshade.models.field import FieldSeries
from geoshade.models.names import derived_names, resolve_name


def keywords(field: FieldSeries) -> list[str]:
    """The quantities ``field``'s file (or the field itself) can show: its own first, then
    the ones it came with and the ones its file lists (``meta["quantities"]``).

    >>> import numpy as np
    >>> f = FieldSeries(np.zeros((2, 2, 2)), name="SWAT", properties={"P": np.ones((2, 2, 2))})
    >>> keywords(f)
    ['SWAT', 'P']
    """
    meta = field.meta or {}
    names = [field.name, *field.properties, *(meta.get("quantities") or ())]
    if field.grid is not None and meta.get("format") == "grid":   # every quantity of the grid
        names += [*field.grid.property_names(), *derived_names(field.grid)]
    return [str(n) for n in dict.fromkeys(n for n in names if n)]


def rekeyed(field: FieldSeries, keyword: str, color_by=None) -> FieldSeries:
    """The field of quantity ``keyword`` of the file ``field`` came from (see the module); one
    line naming what there is when it has no such quantity.

    >>> import numpy as np
    >>> f = FieldSeries(np.zeros((2, 2, 2)), name="SWAT", properties={"P": np.ones((2, 2, 2))})
    >>> g = rekeyed(f, "p")
    >>> g.name, sorted(g.properties), float(g.step(0).max())
    ('P', ['SWAT'], 1.0)
    """
    meta = field.meta or {}
    where = field.source or field.name
    name = resolve_name(keyword, keywords(field), "keyword", where)
    if name == field.name:
        return field
    if field.grid is not None and meta.get("format") == "grid":   # a grid opened as iso
        return field_of(field.grid, name, color_by)
    source = meta.get("egrid") or field.source
    if source and meta.get("format") and Path(str(source)).exists():   # read again, as opened
        return refined_hosts_hidden(load_field(source, keyword=name, color_by=color_by))
    if name in field.properties:   # arrays given: one of the field's own properties
        props = {k: v for k, v in field.properties.items() if k != name}
        props[field.name] = field.values
        return dataclasses.replace(field, values=field.properties[name], name=name,
                                   properties=props, unit="")
    raise InputError(f"{where}: keyword {name}: not readable again (the field was given as "
                     "arrays without it); open the file with that keyword")


__all__ = ["keywords", "rekeyed"]
