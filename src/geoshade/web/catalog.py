"""What a browser may open: the files named on the command line and the files under ``--root``.

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

from pathlib import Path

from geoshade.errors import InputError

#: files under ``--root`` listed at most (the rest are still reachable by name)
MAX_LISTED = 2000
#: suffixes listed from ``--root`` (what :func:`geoshade.load` reads; folders: stores)
LISTED_SUFFIXES = (".egrid", ".grdecl", ".data", ".npy", ".npz", ".raw", ".nhdr", ".nrrd",
                   ".tif", ".tiff", ".h5", ".hdf5", ".nc", ".zarr", ".roff", ".vtk", ".vti",
                   ".mhd", ".parquet", ".csv", ".gsgrid", ".gscore")


class Catalog:
    """The files a browser may open, by name.

    Parameters
    ----------
    paths : list of path
        Files (or store folders) named on the command line; each must exist.
    root : path, optional
        A folder whose files may be opened too, by their path relative to it.
    """

    def __init__(self, paths=(), root=None):
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
        if not self._named and self.root is None:
            raise InputError("serve: name at least one file to show, or a folder with --root")

    def names(self) -> list[str]:
        """The names the browser lists: the named files, then the root's files (relative)."""
        out = list(self._named)
        if self.root is not None:
            found = []
            for p in sorted(self.root.rglob("*")):
                if len(found) >= MAX_LISTED:
                    break
                if (p.suffix.lower() in LISTED_SUFFIXES
                        and not any(part.startswith(".")
                                    for part in p.relative_to(self.root).parts)
                        and p.resolve().is_relative_to(self.root)):  # no link out of the root
                    found.append("root/" + p.relative_to(self.root).as_posix())
            out += found
        return out

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
