"""What a browser may open: the files named on the command line, the files under ``--root`` and,
with ``--demo``, the built-in synthetic data of each part (names ``demo/core`` ...).

The browser never sends a path. It sends a *name* from the list this module gives it; a name is
looked up here, and a name under the root is resolved and checked to stay inside it (``..``,
absolute names and symbolic links that leave the root are refused).

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp()); _ = (d / "a.npy").write_bytes(b"")
>>> cat = Catalog([d / "a.npy"])
>>> cat.names()
['a.npy']
>>> cat.path("a.npy") == (d / "a.npy").resolve()
True
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from geoshade.api import KINDS
from geoshade.errors import InputError
from geoshade.io import formats

#: files under ``--root`` listed at most (the rest are still reachable by name)
MAX_LISTED = 2000
#: suffixes of the pictures the drape picker lists (a GeoTIFF is placed by its georeference)
IMAGE_SUFFIXES = (".tif", ".tiff", ".png", ".jpg", ".jpeg")


class Catalog:
    """The files a browser may open, by name.

    Parameters
    ----------
    paths : list of path
        Files (or store folders) named on the command line; each must exist.
    root : path, optional
        A folder whose files may be opened too, by their path relative to it.
    demo : bool or str
        List the built-in synthetic data of every part (a part's name: that one first), as
        ``demo/<part>`` (:meth:`demo_kind`).
    """

    def __init__(self, paths=(), root=None, demo: bool | str = False):
        if demo not in (True, False) and demo not in KINDS:
            raise InputError(f"--demo: unknown part {demo!r}; expected one of "
                             f"{', '.join(KINDS)}")
        self.demos: list[str] = [] if not demo else sorted(KINDS, key=lambda k: k != demo)
        self._named: dict[str, Path] = {}
        for p in paths:
            path = Path(p).expanduser()
            if not path.exists():
                raise InputError(f"{p}: no such file or folder")
            name = path.name
            k = 2
            while name in self._named:  # two files of the same name in two folders
                name = f"{path.name} ({k})"
                k += 1
            self._named[name] = path.resolve()
        self.root: Path | None = None
        if root is not None:
            r = Path(root).expanduser()
            if not r.is_dir():
                raise InputError(f"--root {root}: not a folder")
            self.root = r.resolve()
        if not self._named and self.root is None and not self.demos:
            raise InputError("serve: name at least one file to show, a folder with --root, "
                             "or --demo")

    def names(self) -> list[str]:
        """The names the browser lists: the named files, then the root's files (relative) of
        every kind :func:`geoshade.load` reads (:func:`geoshade.io.formats.listed`: the format
        table; a store or a folder of TIFF slices is one name, its insides are not listed)."""
        return [f"demo/{k}" for k in self.demos] + list(self._named) \
            + self._under_root(formats.listed)

    def images(self) -> list[str]:
        """The names of the pictures a stack model's top may be draped with (named files and
        the root's files ending in :data:`IMAGE_SUFFIXES`), for the drape picker."""
        return [n for n, p in self._named.items() if p.suffix.lower() in IMAGE_SUFFIXES] \
            + self._under_root(lambda p: p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES)

    def _under_root(self, wanted: Callable[[Path], bool]) -> list[str]:
        """``root/<relative>`` names of the root's entries ``wanted`` takes, in name order (no
        hidden ones, no link out of the root, nothing inside an entry taken; at most
        :data:`MAX_LISTED`)."""
        found: list[str] = []
        if self.root is None:
            return found
        for folder, dirs, files in os.walk(self.root):
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            here = Path(folder)
            for name in sorted([*dirs, *files]):
                p = here / name
                if name.startswith(".") or not wanted(p) \
                        or not p.resolve().is_relative_to(self.root):  # no link out of the root
                    continue
                found.append("root/" + p.relative_to(self.root).as_posix())
                if name in dirs:
                    dirs.remove(name)   # a store or a folder of slices: one entry
        return sorted(found)[:MAX_LISTED]

    def demo_kind(self, name: str) -> str | None:
        """The part of a ``demo/<part>`` name this catalogue lists, else None."""
        name = str(name)
        kind = name[len("demo/"):] if name.startswith("demo/") else None
        return kind if kind in self.demos else None

    def check(self, name: str) -> None:
        """InputError unless the browser may open ``name`` (a listed demo or :meth:`path`)."""
        if self.demo_kind(name) is None:
            self.path(name)

    def path(self, name: str) -> Path:
        """The file behind ``name``; InputError for any name not in the catalogue or leaving
        the root."""
        name = str(name)
        if name in self._named:
            return self._named[name]
        if self.root is not None and name.startswith("root/"):
            rel = name[len("root/"):]
            if rel and not rel.startswith(("/", "\\")) and "\x00" not in rel:
                p = (self.root / rel).resolve()
                if p.is_relative_to(self.root) and p.exists():
                    return p
        raise InputError(f"open: {name!r} is not one of the files this server shows")
