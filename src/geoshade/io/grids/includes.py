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


#: INCLUDE opens one deck may make in all, and re-reads of one file: 23 files each including the
#: next twice would otherwise open 2^22 files from 108 KB (only the depth is bounded by nesting)
MAX_INCLUDE_OPENS = 10_000
MAX_SAME_FILE = 64


def count_open(opened: dict, path: Path, root: Path) -> None:
    """Count one INCLUDE of ``path`` in ``opened`` (path -> times), refusing in one line a deck
    past :data:`MAX_INCLUDE_OPENS` opens in all or :data:`MAX_SAME_FILE` reads of one file.

    Examples
    --------
    >>> seen = {}
    >>> for _ in range(MAX_SAME_FILE):
    ...     count_open(seen, Path("a.inc"), Path("C.DATA"))
    >>> count_open(seen, Path("a.inc"), Path("C.DATA"))
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: a.inc: INCLUDEd 65 times by C.DATA and its INCLUDEs ...
    """
    key = str(path)
    opened[key] = opened.get(key, 0) + 1
    total = sum(opened.values())
    if opened[key] > MAX_SAME_FILE:
        raise InputError(f"{path}: INCLUDEd {opened[key]} times by {root.name} and its INCLUDEs "
                         f"(at most {MAX_SAME_FILE}); files that include each other more than "
                         "once multiply the reading")
    if total > MAX_INCLUDE_OPENS:
        raise InputError(f"{root}: more than {MAX_INCLUDE_OPENS:,} INCLUDE files opened in all "
                         f"(the last {path}); files that include each other more than once "
                         "multiply the reading")


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


__all__ = ["MAX_INCLUDE_OPENS", "MAX_SAME_FILE", "count_open", "missing_error", "missing_text",
           "resolve_include"]
