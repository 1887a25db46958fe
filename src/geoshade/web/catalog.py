"""What a browser may open: the files named on the command line, the files under ``--root`` and,
with ``--demo``, the built-in synthetic data of each part (names ``demo/core`` ...).

The browser never sends a path. It sends a *name* from the list this module gives it; a name is
looked up here, and a name under the root is resolved and checked to stay inside it (``..``,
absolute names and symbolic links that leave the root are refused).

Nothing here can hang the server: the listing reads folder entries only (no file is opened, a
symbolic link loop or a link out of the root is left out, so is a FIFO, a device or a socket,
and at most :data:`MAX_WALKED` entries are looked at), and :meth:`Catalog.checked`, run before
a file is read, refuses a loop, a special file, or a store or case holding one (a FIFO named
``zarr.json`` would block its reader for ever) in one line. Messages to the page name files as
the page knows them (:meth:`Catalog.public`): never the server's absolute paths.

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp()); _ = (d / "a.npy").write_bytes(b"")
>>> cat = Catalog([d / "a.npy"])
>>> cat.names()
['a.npy']
>>> cat.path("a.npy") == (d / "a.npy").resolve()
True
>>> cat.public(f"{d / 'a.npy'}: not a readable .npy array")
'a.npy: not a readable .npy array'
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

from geoshade.api import KINDS
from geoshade.errors import InputError
from geoshade.io import formats

#: files under ``--root`` listed at most (the rest are still reachable by name)
MAX_LISTED = 2000
#: folder entries the listing looks at, at most (a huge root is listed in part, never hangs)
MAX_WALKED = 100_000
#: entries of a store or a folder of slices checked before it is read (:meth:`Catalog.checked`)
MAX_CHECKED = 20_000
#: suffixes of the pictures the drape picker lists (a GeoTIFF is placed by its georeference)
IMAGE_SUFFIXES = (".tif", ".tiff", ".png", ".jpg", ".jpeg")
#: what each kind of special file is called in messages
_SPECIAL = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
            (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
#: a path's folders, where no known one stands before it (:meth:`Catalog.public`)
_FOLDERS = re.compile(r"(?<![\w.~:/<-])/(?:[\w.+@%~-]+/)+")


def _special(mode: int) -> str | None:
    return next((name for test, name in _SPECIAL if test(mode)), None)


def _real(path: Path) -> Path | None:
    """``path`` with every link followed, or None where that cannot be done (a loop, a link to
    nothing, no permission)."""
    try:
        return Path(os.path.realpath(path, strict=True))
    except (OSError, RuntimeError, ValueError):
        return None


class Catalog:
    """The files a browser may open, by name.

    Parameters
    ----------
    paths : list of path
        Files (or store folders) named on the command line; each must exist and be a file or a
        folder (a FIFO, a device or a socket is refused here).
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
        #: (absolute path, how the page knows it), longest first: what :meth:`public` replaces
        self._known: list[tuple[str, str]] = []
        for p in paths:
            path = Path(p).expanduser()
            real = _real(path)
            if real is None:
                raise InputError(f"{p}: no such file or folder" if not os.path.lexists(path)
                                 else f"{p}: a symbolic link that leads nowhere (or a loop)")
            special = _special(os.stat(real).st_mode)
            if special is not None:
                raise InputError(f"{p}: is {special}; serve shows files and folders")
            name = path.name
            k = 2
            while name in self._named:  # two files of the same name in two folders
                name = f"{path.name} ({k})"
                k += 1
            self._named[name] = real
            self._known += [(str(real), name), (str(path.absolute()), name)]
        self.root: Path | None = None
        if root is not None:
            r = Path(root).expanduser()
            if not r.is_dir():
                raise InputError(f"--root {root}: not a folder")
            self.root = r.resolve()
            self._known += [(str(self.root), "root"), (str(r.absolute()), "root")]
        self._known.sort(key=lambda k: -len(k[0]))
        self._patterns = [(re.compile(re.escape(a) + r"(?![^/\s'\":,;)\]])"), b)
                          for a, b in self._known if a != "/"]
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
        hidden ones, no link out of the root or in a loop, no special file, nothing inside an
        entry taken; at most :data:`MAX_LISTED`, after looking at :data:`MAX_WALKED` entries at
        most)."""
        found: list[str] = []
        if self.root is None:
            return found
        folders, walked = [self.root], 0
        while folders and walked < MAX_WALKED:
            here = folders.pop()
            try:
                with os.scandir(here) as it:
                    entries = sorted(it, key=lambda e: e.name)
            except OSError:
                continue
            walked += len(entries)
            for e in entries:
                if e.name.startswith("."):
                    continue
                p = Path(e.path)
                kind = self._kind(e)
                if kind is None:
                    continue
                if wanted(p):
                    found.append("root/" + p.relative_to(self.root).as_posix())
                elif kind == "folder" and not e.is_symlink():
                    folders.append(p)   # a store or a folder of slices: one entry, not entered
        return sorted(found)[:MAX_LISTED]

    def _kind(self, e: os.DirEntry) -> str | None:
        """"file" or "folder" for an entry the listing may show, else None (a special file, a
        link out of the root, in a loop or to nothing); no file is opened."""
        try:
            if e.is_symlink():
                real = _real(Path(e.path))
                if real is None or not real.is_relative_to(self.root):  # type: ignore[arg-type]
                    return None
                mode = os.stat(real).st_mode
            else:
                mode = e.stat(follow_symlinks=False).st_mode
        except OSError:
            return None
        return "folder" if stat.S_ISDIR(mode) else "file" if stat.S_ISREG(mode) else None

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
        the root (or in a loop of links)."""
        name = str(name)
        if name in self._named:
            return self._named[name]
        if self.root is not None and name.startswith("root/"):
            rel = name[len("root/"):]
            if rel and not rel.startswith(("/", "\\")) and "\x00" not in rel \
                    and not any(part.startswith(".") for part in rel.split("/")):
                p = _real(self.root / rel)
                if p is not None and p.is_relative_to(self.root):
                    return p
        raise InputError(f"open: {name!r} is not one of the files this server shows")

    def checked(self, name: str) -> Path:
        """:meth:`path`, checked so that reading it cannot block: a regular file or a folder,
        neither a FIFO, a device nor a socket, and no such thing among the files read with it
        (the case files beside it sharing its stem; the first :data:`MAX_CHECKED` entries of a
        store or a folder of slices). One line naming ``name`` otherwise."""
        p = self.path(name)
        special = _special(os.stat(p).st_mode)
        if special is not None:
            raise InputError(f"{name}: is {special}, not a file; serve reads regular files and "
                             "folders")
        if p.is_dir():
            bad = self._special_inside(p)
            if bad is not None:
                raise InputError(f"{name}: {bad[0]} inside it is {bad[1]}; serve reads regular "
                                 "files only")
            return p
        stem = p.name.split(".")[0].lower()
        try:
            with os.scandir(p.parent) as it:
                beside = [e for e in it if e.name.split(".")[0].lower() == stem
                          and e.name != p.name]
        except OSError:
            beside = []
        for e in beside:
            kind = self._entry_special(e)
            if kind is not None:
                raise InputError(f"{name}: {e.name} beside it is {kind}; serve reads regular "
                                 "files only")
        return p

    @staticmethod
    def _entry_special(e: os.DirEntry) -> str | None:
        try:
            if e.is_symlink():
                real = _real(Path(e.path))
                if real is None:
                    return "a symbolic link loop (or a link to nothing)"
                return _special(os.stat(real).st_mode)
            return _special(e.stat(follow_symlinks=False).st_mode)
        except OSError:
            return None

    def _special_inside(self, folder: Path) -> tuple[str, str] | None:
        """(relative name, what it is) of the first special file or link loop among the first
        :data:`MAX_CHECKED` entries under ``folder``, else None."""
        folders, seen = [folder], 0
        while folders and seen < MAX_CHECKED:
            here = folders.pop()
            try:
                with os.scandir(here) as it:
                    entries = list(it)
            except OSError:
                continue
            seen += len(entries)
            for e in entries:
                kind = self._entry_special(e)
                if kind is not None:
                    return Path(e.path).relative_to(folder).as_posix(), kind
                if e.is_dir(follow_symlinks=False):
                    folders.append(Path(e.path))
        return None

    def public(self, value: Any) -> Any:
        """``value`` (a message's text, or a message) as the page may see it: a named file's
        absolute path becomes its name, the root's ``root``, any other absolute path its last
        part (the server's folders are not the page's business).

        >>> Catalog([], demo=True).public({"text": "/home/me/data/x.npy: too big"})
        {'text': 'x.npy: too big'}
        """
        if isinstance(value, str):
            if "/" not in value or value.startswith("<svg"):   # a plot has no path
                return value
            for pattern, name in self._patterns:
                value = pattern.sub(name, value)
            return _FOLDERS.sub("", value)
        if isinstance(value, dict):
            return {k: self.public(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [self.public(v) for v in value]
        return value
