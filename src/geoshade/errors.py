"""Errors that carry one clear line for the user.

Every error geoshade raises on bad input is a :class:`GeoshadeError`: its message names the
file (when there is one), the field and what was expected.  The CLI prints ``str(err)`` and exits
with status 2; it never shows a traceback for these.
"""

from __future__ import annotations

import importlib
import re
from types import ModuleType

#: The CLI's exit codes, one per kind of failure (``geoshade --help`` lists them; each
#: :class:`GeoshadeError` subclass that sets ``exit_code`` takes its own from here).
EXIT_CODES: dict[str, int] = {
    "ok": 0,
    "bad input or arguments": 2,
    "no usable OpenGL": 3,
    "does not fit the GPU": 4,
    "shader failed to build": 5,
    "not enough memory on this machine": 6,
    "optional package missing": 7,
    "desktop viewer cannot start": 8,
    "disk full": 9,
    "a bug (traceback written to a file)": 70,
    "operating-system error": 74,
    "store busy (another ingest writes it): try again later": 75,
    "interrupted (Ctrl-C)": 130,
    "closed output pipe": 141,
}
EXIT_INPUT = EXIT_CODES["bad input or arguments"]
EXIT_GL = EXIT_CODES["no usable OpenGL"]
EXIT_GPU_MEMORY = EXIT_CODES["does not fit the GPU"]
EXIT_SHADER = EXIT_CODES["shader failed to build"]
EXIT_MEMORY = EXIT_CODES["not enough memory on this machine"]
EXIT_EXTRA = EXIT_CODES["optional package missing"]
EXIT_VIEWER = EXIT_CODES["desktop viewer cannot start"]
EXIT_DISK_FULL = EXIT_CODES["disk full"]
EXIT_BUG = EXIT_CODES["a bug (traceback written to a file)"]
EXIT_OS = EXIT_CODES["operating-system error"]
EXIT_BUSY = EXIT_CODES["store busy (another ingest writes it): try again later"]
EXIT_INTERRUPTED = EXIT_CODES["interrupted (Ctrl-C)"]
EXIT_PIPE = EXIT_CODES["closed output pipe"]


def exit_codes_text() -> str:
    """The exit codes as lines for ``--help``.

    >>> print(exit_codes_text().splitlines()[1])
      2  bad input or arguments
    """
    return "\n".join(f"{code:>3}  {what}" for what, code in EXIT_CODES.items())


class GeoshadeError(Exception):
    """Base class: a problem the user can fix (bad input, missing capability)."""

    exit_code = EXIT_INPUT


class InputError(GeoshadeError, ValueError):
    """A file, argument or array does not have the expected content."""


class GLUnavailableError(GeoshadeError, RuntimeError):
    """No usable OpenGL (>= 4.3) context could be created."""

    exit_code = EXIT_GL


class GPUMemoryError(GeoshadeError, MemoryError):
    """The requested data does not fit into the GPU (memory or texture size)."""

    exit_code = EXIT_GPU_MEMORY


class MissingExtraError(GeoshadeError, ImportError):
    """An optional package of one of geoshade's extras (``pip install 'geoshade[EXTRA]'``) is
    missing; the message names the package and the extra that installs it."""

    exit_code = EXIT_EXTRA


#: what the dynamic loader says when a library cannot be mapped for want of address space
_NO_MEMORY = re.compile(r"failed to map segment|cannot allocate memory|out of memory", re.I)


def require(module: str, extra: str, what: str) -> ModuleType:
    """Import and return ``module``, an optional dependency installed by the extra ``extra``.

    Parameters
    ----------
    module : str
        Dotted module name, e.g. ``"xarray"`` or ``"imageio.v2"``.
    extra : str
        The geoshade extra that installs it (``netcdf``, ``parquet``, ``hdf5``, ``distributed``,
        ``video``).
    what : str
        What needs it, for the message: ``"reading GeoTOP netCDF"``.

    Raises
    ------
    MissingExtraError
        One line naming the package and the extra.

    Examples
    --------
    >>> require("json", "none", "parsing").__name__
    'json'
    >>> try:
    ...     require("no_such_pkg", "netcdf", "reading netCDF")
    ... except MissingExtraError as err:
    ...     print(err)
    reading netCDF needs no_such_pkg, which is not installed: pip install 'geoshade[netcdf]'
    """
    top = module.split(".")[0]
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if _NO_MEMORY.search(str(exc)):  # installed: its library could not be mapped (ulimit -v)
            raise MemoryError(f"loading {top}: {str(exc).strip().splitlines()[0]}") from None
        missing = (exc.name or "").split(".")[0]
        if missing in ("", top):
            why = "which is not installed"
        else:  # installed, but something it imports is missing or broken
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            why = f"which cannot be imported ({first})"
        raise MissingExtraError(f"{what} needs {top}, {why}: pip install 'geoshade[{extra}]'"
                                ) from None


class GeoshadeDeprecationWarning(FutureWarning):
    """An option or flag that still works under its old name; the message names the new one.

    A ``FutureWarning`` so that users see it (Python shows these by default); the CLI prints it
    as one ``geoshade: warning:`` line.
    """


class EmptySceneWarning(UserWarning):
    """The picture is an empty scene: the selection, filter, level, plane or hidden materials
    left nothing to draw (the one warning every View gives; the message says why)."""


_CONTROL = {c: f"\\x{c:02x}" for c in (*range(0x00, 0x09), *range(0x0b, 0x20), 0x7f)}
_CONTROL.update({c: f"\\u{c:04x}" for c in range(0x80, 0xa0)})


def terminal_safe(text: str) -> str:
    r"""``text`` with control characters escaped (newlines and tabs kept), so that names and
    units read from files cannot drive the terminal (escape sequences clear the screen, set the
    window title or write the clipboard).

    Examples
    --------
    >>> terminal_safe("well \x1b]52;c;ZXZpbA==\x07 A\nB")
    'well \\x1b]52;c;ZXZpbA==\\x07 A\nB'
    """
    return str(text).translate(_CONTROL)


def where(path) -> str:
    """Prefix for messages about a file: ``'path: '`` or ``''``."""
    return f"{path}: " if path else ""
