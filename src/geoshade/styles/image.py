"""The size of a rendered picture (shared by every part's render function)."""

from __future__ import annotations

from geoshade.errors import InputError

MAX_SIDE = 16384


def parse_size(size) -> tuple[int, int]:
    """``(w, h)`` or ``"WxH"`` -> (w, h), checked.

    >>> parse_size("320x240"), parse_size((8, 6))
    ((320, 240), (8, 6))
    """
    if isinstance(size, str):
        try:
            w, h = (int(v) for v in size.lower().split("x"))
        except ValueError:
            raise InputError(
                f"size: expected WIDTHxHEIGHT such as 1024x768, got {size!r}") from None
    else:
        try:
            w, h = (int(v) for v in size)
        except (TypeError, ValueError):
            raise InputError(f"size: expected (width, height), got {size!r}") from None
    if w < 1 or h < 1 or w > MAX_SIDE or h > MAX_SIDE:
        raise InputError(f"size: {w}x{h} is outside 1..{MAX_SIDE} pixels per side")
    return w, h
