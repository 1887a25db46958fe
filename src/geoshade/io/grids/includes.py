"""INCLUDE files of GRDECL files and decks: where a name points, and the one line that names
every INCLUDE that is not there.

A name is looked for relative to the including file, then to the deck (the root file);
``'$ALIAS/file'`` takes the folder from PATHS, else from an environment variable.  A reader
does not stop at the first missing INCLUDE: it reads on, so that one error (or, with
``skip_missing``, one warning) names them all.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from geoshade.errors import InputError
from geoshade.io.paths import check_file


def resolve_include(name: str, including: Path, root: Path, aliases: dict) -> Path | None:
    """An INCLUDE name -> existing path: relative to the including file, then to the root;
    None where there is no such file."""
    raw = name.strip()
    m = re.match(r"^\$([A-Za-z_][A-Za-z0-9_]*)[/\\]?(.*)$", raw)
    cands = [Path(raw)]
    if m:
        base = aliases.get(m.group(1).upper()) or os.environ.get(m.group(1))
        cands = [*([Path(base) / m.group(2)] if base else []), Path(m.group(2))]
    for c in cands:
        for base in (including.parent, root.parent):
            p = c if c.is_absolute() else base / c
            if p.exists():   # a FIFO or a folder under that name: one line, not a hang
                return check_file(p, f"a file to INCLUDE (from {including.name})")
    return None


def missing_text(missing: list[tuple[str, Path]]) -> str:
    """``'a.inc', 'b.inc' (looked in DIR)`` for INCLUDEs ``(name, including file)`` not found.

    Examples
    --------
    >>> missing_text([("a.inc", Path("d/C.DATA")), ("b.inc", Path("d/C.DATA"))])
    "'a.inc', 'b.inc' (looked in d)"
    >>> missing_text([("a.inc", Path("d/C.DATA")), ("b.inc", Path("d/g/x.inc"))])
    "'a.inc' (looked in d), 'b.inc' (looked in d/g)"
    """
    dirs = {str(inc.parent) for _, inc in missing}
    if len(dirs) == 1:
        return f"{', '.join(repr(n) for n, _ in missing)} (looked in {dirs.pop()})"
    return ", ".join(f"{n!r} (looked in {inc.parent})" for n, inc in missing)


def missing_error(root: Path, missing: list[tuple[str, Path]]) -> InputError:
    """The one line for INCLUDEs not found: each named, and how to read the rest."""
    hint = "; --skip-missing reads the rest"
    if len(missing) == 1:
        name, inc = missing[0]
        return InputError(f"{inc}: INCLUDE {name!r}: no such file (looked in {inc.parent})"
                          f"{hint}")
    return InputError(f"{root}: {len(missing)} INCLUDE files are missing: "
                      f"{missing_text(missing)}{hint}")


__all__ = ["missing_error", "missing_text", "resolve_include"]
