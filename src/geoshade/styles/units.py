"""Units of lengths and of the ECLIPSE/OPM keywords for colour bars and scale bars: the names of
:mod:`geoshade.models.units`, where they are declared (a model's values are in them whether or
not anything draws it)."""

from __future__ import annotations

from geoshade.models.units import (
    KEYWORD_UNITS,
    SYSTEMS,
    case_unit_system,
    expression_unit,
    keyword_unit,
    length_unit,
    unit_system,
    value_unit,
)

__all__ = ["KEYWORD_UNITS", "SYSTEMS", "case_unit_system", "expression_unit",
           "keyword_unit", "length_unit", "unit_system", "value_unit"]
