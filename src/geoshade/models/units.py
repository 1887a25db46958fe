"""Units of lengths and of the common ECLIPSE/OPM keywords: what the values of a model are in.

ECLIPSE files do not store a unit per array: it follows from the keyword and the case's unit
system (``METRIC``, ``FIELD``, ``LAB``, ``PVT-M``: the deck's RUNSPEC, item 3 of the INIT's or
restart's ``INTEHEAD``; else the EGRID's ``GRIDUNIT`` ``METRES``/``FEET``/``CM``).

:func:`case_unit_system` and :func:`value_unit` are the one source every part (grid, iso, wells,
picks, exports, the xarray/JSON outputs) takes the unit of a shown value from. They live with
the models (they read only a model's ``meta``, ``units`` and ``unit``), so a model's
``to_xarray()`` has its units whatever was imported before; :mod:`geoshade.styles.units` gives
the same names to the colour bars.

>>> keyword_unit("PERMX"), keyword_unit("PRESSURE", "FIELD"), keyword_unit("SWAT")
('mD', 'psia', 'fraction')
>>> keyword_unit("PRESSURE", "PVT-M"), keyword_unit("RS", "FIELD")
('atm', 'Mscf/stb')
>>> length_unit("METRES"), length_unit("FEET"), length_unit("um")
('m', 'ft', 'um')
"""

from __future__ import annotations

import re

#: keyword (or prefix ending in ``*``) -> unit per unit system (METRIC, FIELD, LAB, PVT-M)
KEYWORD_UNITS: dict[str, tuple[str, str, str, str]] = {
    "PERM*": ("mD", "mD", "mD", "mD"),
    "PORO": ("fraction", "fraction", "fraction", "fraction"),
    "NTG": ("fraction", "fraction", "fraction", "fraction"),
    "SWAT": ("fraction", "fraction", "fraction", "fraction"),
    "SGAS": ("fraction", "fraction", "fraction", "fraction"),
    "SOIL": ("fraction", "fraction", "fraction", "fraction"),
    "SWL": ("fraction", "fraction", "fraction", "fraction"),
    "SWCR": ("fraction", "fraction", "fraction", "fraction"),
    "SOWCR": ("fraction", "fraction", "fraction", "fraction"),
    "PRESSURE": ("bar", "psia", "atm", "atm"),
    "PRES*": ("bar", "psia", "atm", "atm"),
    "DEPTH": ("m", "ft", "cm", "m"),
    "DX": ("m", "ft", "cm", "m"),
    "DY": ("m", "ft", "cm", "m"),
    "DZ": ("m", "ft", "cm", "m"),
    "TOPS": ("m", "ft", "cm", "m"),
    "PORV": ("rm³", "rb", "rcc", "rm³"),
    "TRAN*": ("cP·rm³/day/bar", "cP·rb/day/psi", "cP·rcc/h/atm", "cP·rm³/day/atm"),
    "RS": ("sm³/sm³", "Mscf/stb", "scc/scc", "sm³/sm³"),
    "RV": ("sm³/sm³", "stb/Mscf", "scc/scc", "sm³/sm³"),
    "TEMP": ("°C", "°F", "°C", "°C"),
}
#: names of the unit systems, in the order of :data:`KEYWORD_UNITS`' tuples
SYSTEMS = ("METRIC", "FIELD", "LAB", "PVT-M")
#: length unit names as files write them -> a short symbol
LENGTHS = {"METRES": "m", "METERS": "m", "METRE": "m", "M": "m", "FEET": "ft", "FT": "ft",
           "CM": "cm", "MM": "mm", "UM": "um", "MICRON": "um", "MICRONS": "um", "KM": "km"}


def keyword_unit(name: str | None, system: str = "METRIC") -> str:
    """The unit of an ECLIPSE keyword in ``system`` ('' where unknown)."""
    if not name:
        return ""
    n = str(name).upper()
    k = SYSTEMS.index(system.upper()) if system and system.upper() in SYSTEMS else 0
    if n in KEYWORD_UNITS:
        return KEYWORD_UNITS[n][k]
    for key, units in KEYWORD_UNITS.items():
        if key.endswith("*") and n.startswith(key[:-1]):
            return units[k]
    return ""


def expression_unit(expr: str | None, system: str = "METRIC") -> str:
    """The unit of a keyword or of an expression over keywords: a keyword's own, ``log10 mD``
    for ``log10(PERMX)``; '' for any other expression (its unit is not known).

    >>> expression_unit("PERMX"), expression_unit("log10(permx)"), expression_unit("PORO*NTG")
    ('mD', 'log10 mD', '')
    """

    text = str(expr or "").strip()
    m = re.fullmatch(r"log10\(\s*([A-Za-z_]\w*)\s*\)", text)
    if m:
        unit = keyword_unit(m.group(1), system)
        return f"log10 {unit}" if unit else ""
    return keyword_unit(text, system) if text.isidentifier() else ""


def length_unit(name: str | None) -> str:
    """A short symbol of a length unit ('' where unknown; other names as they are)."""
    if not name:
        return ""
    return LENGTHS.get(str(name).strip().upper(), str(name).strip())


def unit_system(length: str | None, declared: str | None = None) -> str:
    """The unit system of a case: the one its deck or INIT file declares (``METRIC FIELD LAB
    PVT-M``), else the one its length unit implies (FEET: FIELD, CM: LAB, else METRIC).

    >>> unit_system("FEET"), unit_system("CM"), unit_system("METRES", declared="LAB")
    ('FIELD', 'LAB', 'LAB')
    >>> unit_system("METRES", declared="pvt-m")
    'PVT-M'
    """
    d = str(declared or "").strip().upper()
    if d in SYSTEMS:
        return d
    return {"ft": "FIELD", "cm": "LAB"}.get(length_unit(length), "METRIC")


def case_unit_system(model) -> str:
    """The unit system of the case ``model`` comes from: a corner-point grid's
    ``meta["unit_system"]`` (RUNSPEC or INTEHEAD) else its length unit; a field series' own
    ``meta["unit_system"]``, else its grid's, else its length unit. The one function every
    part asks.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(2, 2, 1)
    >>> case_unit_system(g)
    'METRIC'
    >>> g.meta["unit_system"] = "FIELD"
    >>> case_unit_system(g)
    'FIELD'
    """
    meta = getattr(model, "meta", None) or {}
    grid = getattr(model, "grid", None)
    if meta.get("unit_system"):
        return unit_system("", meta["unit_system"])
    if grid is not None and grid is not model:
        return case_unit_system(grid)
    length = getattr(model, "units", None) or getattr(model, "length_unit", None)
    return unit_system(length)


def value_unit(model, name: str | None) -> str:
    """The unit of the values of ``name`` (a keyword or an expression over keywords) shown
    from ``model`` (a corner-point grid or a field series): a field series' own ``unit`` for
    its own quantity when it has one, else the keyword's unit in :func:`case_unit_system`.
    Every colour bar, pick read-out and JSON takes its unit from here.

    >>> from geoshade.compute.grid.synthetic import synthetic_grid
    >>> g = synthetic_grid(2, 2, 1)
    >>> g.meta["unit_system"] = "FIELD"
    >>> value_unit(g, "PRESSURE"), value_unit(g, "log10(PERMX)"), value_unit(g, None)
    ('psia', 'log10 mD', '')
    """
    if not name:
        return ""
    if str(name) == str(getattr(model, "name", None) or "") and getattr(model, "unit", None):
        return str(model.unit)
    return expression_unit(name, case_unit_system(model))


__all__ = ["KEYWORD_UNITS", "SYSTEMS", "case_unit_system", "expression_unit",
           "keyword_unit", "length_unit", "unit_system", "value_unit"]
