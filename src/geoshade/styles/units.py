"""Units of lengths and of the common ECLIPSE/OPM keywords, for colour bars and scale bars.

ECLIPSE files do not store a unit per array: it follows from the keyword and the case's unit
system (``METRIC``, ``FIELD``, ``LAB``; the EGRID's ``GRIDUNIT`` says ``METRES``/``FEET``).

>>> keyword_unit("PERMX"), keyword_unit("PRESSURE", "FIELD"), keyword_unit("SWAT")
('mD', 'psia', 'fraction')
>>> length_unit("METRES"), length_unit("FEET"), length_unit("um")
('m', 'ft', 'um')
"""

from __future__ import annotations

#: keyword (or prefix ending in ``*``) -> unit per unit system (METRIC, FIELD, LAB)
KEYWORD_UNITS: dict[str, tuple[str, str, str]] = {
    "PERM*": ("mD", "mD", "mD"),
    "PORO": ("fraction", "fraction", "fraction"),
    "NTG": ("fraction", "fraction", "fraction"),
    "SWAT": ("fraction", "fraction", "fraction"),
    "SGAS": ("fraction", "fraction", "fraction"),
    "SOIL": ("fraction", "fraction", "fraction"),
    "SWL": ("fraction", "fraction", "fraction"),
    "SWCR": ("fraction", "fraction", "fraction"),
    "SOWCR": ("fraction", "fraction", "fraction"),
    "PRESSURE": ("bar", "psia", "atm"),
    "PRES*": ("bar", "psia", "atm"),
    "DEPTH": ("m", "ft", "cm"),
    "DX": ("m", "ft", "cm"),
    "DY": ("m", "ft", "cm"),
    "DZ": ("m", "ft", "cm"),
    "TOPS": ("m", "ft", "cm"),
    "PORV": ("rm³", "rb", "rcc"),
    "TRAN*": ("cP·rm³/day/bar", "cP·rb/day/psi", "cP·rcc/h/atm"),
    "RS": ("sm³/sm³", "Mscf/stb", "scc/scc"),
    "RV": ("sm³/sm³", "stb/Mscf", "scc/scc"),
    "TEMP": ("°C", "°F", "°C"),
}
#: names of the unit systems, in the order of :data:`KEYWORD_UNITS`' tuples
SYSTEMS = ("METRIC", "FIELD", "LAB")
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
    import re

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
    """The unit system of a case: the one its deck declares (``METRIC FIELD LAB``; PVT-M is
    metric), else the one its length unit implies (FEET: FIELD, CM: LAB, else METRIC).

    >>> unit_system("FEET"), unit_system("CM"), unit_system("METRES", declared="LAB")
    ('FIELD', 'LAB', 'LAB')
    """
    d = str(declared or "").upper()
    if d in SYSTEMS:
        return d
    if d == "PVT-M":
        return "METRIC"
    return {"ft": "FIELD", "cm": "LAB"}.get(length_unit(length), "METRIC")


__all__ = ["KEYWORD_UNITS", "expression_unit", "keyword_unit", "length_unit", "unit_system"]
