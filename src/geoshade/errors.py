"""Errors that carry one clear line for the user.

Every error geoshade raises on bad input is a :class:`GeoshadeError`: its message names the
file (when there is one), the field and what was expected.  The CLI prints ``str(err)`` and exits
with status 2; it never shows a traceback for these.
"""

from __future__ import annotations


class GeoshadeError(Exception):
    """Base class: a problem the user can fix (bad input, missing capability)."""

    exit_code = 2


class InputError(GeoshadeError, ValueError):
    """A file, argument or array does not have the expected content."""


class GLUnavailableError(GeoshadeError, RuntimeError):
    """No usable OpenGL (>= 4.3) context could be created."""

    exit_code = 3


class GPUMemoryError(GeoshadeError, MemoryError):
    """The requested data does not fit into the GPU (memory or texture size)."""

    exit_code = 4


def where(path) -> str:
    """Prefix for messages about a file: ``'path: '`` or ``''``."""
    return f"{path}: " if path else ""
