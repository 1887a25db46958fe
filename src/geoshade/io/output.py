"""Atomic writers for what geoshade produces (images, JSON, text, stores).

Every output is written to a temporary file (or folder) in the destination folder and moved into
place by :func:`publish`, the one atomic publish of the package (files with :func:`os.replace`,
stores by renaming the finished folder), so a reader never sees half a file or half a store and
an interrupted run leaves the old one.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import stat
import tempfile
import uuid
from pathlib import Path

import numpy as np
from PIL import Image

from geoshade.errors import InputError


def publish(staged, final, checked: bool = False) -> Path:
    """Move a finished output ``staged`` into place as ``final``: the one atomic publish.

    A file gets a normal file's mode (``0666`` less the umask) and replaces ``final`` at once
    (:func:`os.replace`: a reader sees the old file or the new one).  A folder (a store) is
    renamed into place; an existing ``final`` is first moved aside under a hidden name and
    removed only after the rename, so a reader never sees half a store (and a failed rename puts
    the old one back).  ``staged`` must be in ``final``'s folder.  An existing ``final`` that
    geoshade must not replace (:func:`check_replace`: a folder it did not write, a link, a
    device) is refused here too, the last guard (``checked``: the caller has checked it, e.g. a
    part of a store it opened).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> _ = atomic_write_bytes(os.path.join(d, "a.txt"), b"old")
    >>> os.mkdir(os.path.join(d, ".a.new")); os.mkdir(os.path.join(d, "s"))
    >>> p = publish(os.path.join(d, ".a.new"), os.path.join(d, "s"))
    >>> sorted(os.listdir(d))
    ['a.txt', 's']
    """
    staged, final = Path(staged), Path(final)
    if staged.is_dir() and not staged.is_symlink():
        if not checked:
            check_replace(final)
        if final.exists() or final.is_symlink():
            old = final.with_name(f".{final.name}.old-{uuid.uuid4().hex[:8]}")
            os.rename(final, old)
            try:
                os.rename(staged, final)
            except BaseException:
                os.rename(old, final)
                raise
            if old.is_dir() and not old.is_symlink():
                shutil.rmtree(old, ignore_errors=True)
            else:
                old.unlink(missing_ok=True)
        else:
            os.rename(staged, final)
    else:
        os.chmod(staged, 0o666 & ~_umask())  # mkstemp makes 0600: a normal file's mode
        os.replace(staged, final)
    return final


#: root attributes by which a folder is known as a store geoshade wrote: a grid store, an
#: ingested (or ``write_zarr(ome=True)``) volume; a ``write_zarr`` array keeps a checksum record
STORE_MARKERS = ("grid_store", "ingest")
#: what a store geoshade wrote holds at its top level (besides ``zarr.json``): a grid store's
#: arrays, index and coarse level, a volume's levels, an array's chunks
STORE_ENTRIES = frozenset({"coord", "zcorn", "actnum", "props", "steps", "index", "lod", "c"})
#: the names geoshade's own unfinished writes leave inside a store (``index.building``,
#: ``lod.partial``, ``lod.lock``, ``.index.old-1a2b3c4d``, ``lod.partial.progress.json``)
_LEFTOVER = re.compile(r"^(\.(?P<a>[^/]+)\.old-[0-9a-f]{8}|(?P<b>[^/.]+)\.(building|partial|lock|"
                       r"partial\.progress\.json))$")
#: the largest ``zarr.json`` read to recognise a store
_META_BYTES = 64 << 20


def read_store_meta(folder) -> dict | None:
    """The ``zarr.json`` of ``folder`` as a dict, or None: read only when it is a regular file
    of sensible size (never a FIFO that would block), its JSON not nested too deep."""
    f = Path(folder) / "zarr.json"
    try:
        if not stat.S_ISREG(os.stat(f).st_mode):   # never opened: a device, a FIFO
            return None
        fd = os.open(f, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            st = os.fstat(fh.fileno())
            if not stat.S_ISREG(st.st_mode) or st.st_size > _META_BYTES:
                return None
            meta = json.loads(fh.read())
    except (OSError, ValueError, RecursionError):
        return None
    return meta if isinstance(meta, dict) else None


def own_store(path) -> bool:
    """Whether the folder ``path`` is a store geoshade wrote: its ``zarr.json`` carries one of
    :data:`STORE_MARKERS` (or, for a ``write_zarr`` array, a checksum record).

    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> own_store(d)
    False
    >>> with open(os.path.join(d, "zarr.json"), "w") as fh:
    ...     _ = fh.write('{"zarr_format": 3, "attributes": {"grid_store": {}}}')
    >>> own_store(d)
    True
    """
    meta = read_store_meta(path)
    attrs = meta.get("attributes") if meta else None
    if not isinstance(attrs, dict):
        return False
    if any(m in attrs for m in STORE_MARKERS):
        return True
    rec = attrs.get("checksums")
    return meta.get("node_type") == "array" and isinstance(rec, dict) and \
        rec.get("algorithm") == "crc32"


def _foreign_entries(folder: Path) -> list[str]:
    """The top-level entries of a store that no geoshade store holds (a user's files)."""
    out = []
    for name in sorted(os.listdir(folder)):
        m = _LEFTOVER.match(name)
        base = (m.group("a") or m.group("b")) if m else name
        if name == "zarr.json" or base in STORE_ENTRIES or (base.isdigit() and len(base) < 4):
            continue
        out.append(name)
    return out


def _resolved(p) -> Path | None:
    try:
        return Path(p).resolve()
    except (OSError, RuntimeError):
        return None


def check_replace(path, inputs=(), flag: str = "-o") -> None:
    """Refuse, in one line and before any work, an existing ``path`` that an output must not
    replace: only a store geoshade wrote (:func:`own_store`, holding nothing else) or a file
    may be replaced (``--overwrite``); never a folder holding other things, the working folder
    or one that holds it, an input or a folder holding one (``inputs``), a device, FIFO or
    socket, or a symbolic link (never followed: the link, not what it names, would go).

    Raises
    ------
    InputError
        One line naming ``path`` and what it is.

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> open(os.path.join(d, "notes.txt"), "w").close()
    >>> check_replace(os.path.join(d, "new.zarr"))        # nothing there: fine
    >>> check_replace(d)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: ...: -o: a folder geoshade did not write (it holds notes.txt); ...
    """
    p = Path(path)
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        return
    except OSError as err:
        raise InputError(f"{path}: {flag}: cannot be checked ({err.strerror or err})") from None
    keep = "; --overwrite replaces only a store geoshade wrote, or a file"
    if stat.S_ISLNK(st.st_mode):
        raise InputError(f"{path}: {flag}: a symbolic link (to {os.readlink(p)}); geoshade never "
                         f"replaces a link or what it names{keep}")
    rp = _resolved(p)
    cwd = _resolved(Path.cwd()) if stat.S_ISDIR(st.st_mode) else None
    if rp is not None and cwd is not None and (rp == cwd or rp in cwd.parents):
        what = "the working folder" if rp == cwd else "a folder holding the working folder"
        raise InputError(f"{path}: {flag}: {what}; geoshade never replaces it{keep}")
    for i in inputs or ():
        ri = None if i is None else _resolved(i)
        if ri is not None and rp is not None and (ri == rp or rp in ri.parents):
            what = "the input" if ri == rp else f"a folder holding the input {ri.name}"
            raise InputError(f"{path}: {flag}: {what}; it would be lost{keep}")
    if stat.S_ISREG(st.st_mode):
        return
    if not stat.S_ISDIR(st.st_mode):
        kind = ("a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else
                "a FIFO" if stat.S_ISFIFO(st.st_mode) else "a socket"
                if stat.S_ISSOCK(st.st_mode) else "a special file")
        raise InputError(f"{path}: {flag}: {kind}, not a file or store geoshade wrote{keep}")
    try:
        entries = os.listdir(p)
    except OSError as err:
        raise InputError(f"{path}: {flag}: a folder that cannot be listed "
                         f"({err.strerror or err}){keep}") from None
    if not entries:
        return   # an empty folder: nothing is lost
    if not own_store(p):
        shown = ", ".join(sorted(entries)[:3]) + (", …" if len(entries) > 3 else "")
        raise InputError(f"{path}: {flag}: a folder geoshade did not write (it holds {shown})"
                         f"{keep}")
    foreign = _foreign_entries(p)
    if foreign:
        shown = ", ".join(foreign[:3]) + (", …" if len(foreign) > 3 else "")
        raise InputError(f"{path}: {flag}: a store geoshade wrote, but it also holds {shown}, "
                         f"which is not part of it{keep}")


def _write_named(open_file, data: bytes, path) -> None:
    """Write ``data`` to the file ``open_file()`` opens and close it; an OS error that names no
    file (a full disk: "No space left on device") names ``path``, the output being written."""
    try:
        with open_file() as fh:
            fh.write(data)
    except OSError as err:
        if err.filename is None:
            err.filename = str(path)
        raise


def atomic_write_bytes(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{path}: output folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        _write_named(lambda: os.fdopen(fd, "wb"), data, path)
        publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_png(path, rgba: np.ndarray) -> Path:
    """Save an ``(h, w, 3|4) uint8`` image as PNG, atomically.

    >>> import numpy as np, tempfile, os
    >>> p = write_png(os.path.join(tempfile.mkdtemp(), "a.png"), np.zeros((2, 3, 4), np.uint8))
    >>> p.suffix
    '.png'
    """
    return atomic_write_bytes(path, png_bytes(rgba))


def write_json(path, obj) -> Path:
    """Write ``obj`` as indented JSON, atomically."""
    return atomic_write_bytes(path, json_bytes(obj))


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


class Outputs:
    """The files one command writes: checked before any work, written together at the end.

    Before any work (the constructor): every output is refused with one line when it is an
    empty name, a folder, in a folder that does not exist or cannot be written, has the wrong
    suffix, names an input (``inputs``, and what :meth:`protect` adds after reading a case:
    INIT, UNRST, INCLUDE files ...) or is given twice. During the work, :meth:`put` (bytes) and
    :meth:`path` (a temporary file in the destination folder for writers that write
    themselves) stage each output; :meth:`commit` moves them all into place at the end. If
    anything fails before or during the commit, the temporary files are removed and the
    outputs this command created are removed again: a failed run leaves no new file.

    Parameters
    ----------
    outputs : dict
        flag (as the user wrote it, for messages) -> path, or None when not given.
    inputs : paths
        Files (or folders) the command reads.
    suffixes : dict
        flag -> allowed suffixes (lower case, e.g. ``(".png",)``).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> with Outputs({"-o": os.path.join(d, "a.png"), "--stats": None}) as out:
    ...     out.put("-o", b"png bytes")
    ...     written = out.commit()
    >>> [p.name for p in written], os.listdir(d)
    (['a.png'], ['a.png'])
    >>> Outputs({"-o": os.path.join(d, "no", "a.png")})
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: .../no/a.png: -o: the folder .../no does not exist
    """

    def __init__(self, outputs: dict, inputs=(), suffixes: dict | None = None):
        self.paths: dict[str, Path] = {}
        self._inputs: list[Path] = []
        self._staged: dict[str, Path] = {}
        self.protect(inputs)
        seen: dict[Path, str] = {}
        for flag, path in outputs.items():
            if path is None:
                continue
            if str(path).strip() == "":
                raise InputError(f"{flag}: expected a file name, got an empty string")
            p = Path(path)
            folder = p.parent if str(p.parent) else Path(".")
            where = f"{path}: {flag}"
            if p.is_dir():
                raise InputError(f"{where} names a folder; expected a file name")
            if p.exists() and not p.is_file():
                raise InputError(f"{where} names a special file (a FIFO or device); expected a "
                                 "regular file name")
            if not folder.is_dir():
                raise InputError(f"{where}: the folder {folder} does not exist")
            if not os.access(folder, os.W_OK | os.X_OK):
                raise InputError(f"{where}: the folder {folder} is not writable")
            want = (suffixes or {}).get(flag)
            if want and not any(str(p).lower().endswith(s) for s in want):
                raise InputError(f"{where}: expected a name ending in {' or '.join(want)}")
            rp = p.resolve()
            if rp in seen:
                raise InputError(f"{path}: given to both {seen[rp]} and {flag}")
            seen[rp] = flag
            self.paths[flag] = p
        self._check_inputs()

    # --- inputs --------------------------------------------------------------------------------
    def protect(self, inputs) -> None:
        """Add files (or folders) the command reads; no output may name one (or lie inside a
        folder one names)."""
        for i in inputs or ():
            if i is None:
                continue
            try:
                self._inputs.append(Path(i).resolve())
            except OSError:
                continue
        if self.paths:
            self._check_inputs()

    def _check_inputs(self) -> None:
        for flag, p in self.paths.items():
            rp = p.resolve()
            for i in self._inputs:
                if rp == i or i in rp.parents:
                    raise InputError(f"{p}: {flag} names an input ({i.name}); it would be "
                                     "overwritten")

    # --- staging -------------------------------------------------------------------------------
    def given(self, flag: str) -> bool:
        return flag in self.paths

    def path(self, flag: str) -> Path:
        """A temporary file in the destination folder (same suffixes) to write ``flag`` to."""
        final = self.paths[flag]
        folder = final.parent if str(final.parent) else Path(".")
        suffix = "".join(final.suffixes) or ".tmp"
        fd, tmp = tempfile.mkstemp(prefix=f".{final.name}.", suffix=suffix, dir=folder)
        os.close(fd)
        old = self._staged.get(flag)
        if old is not None:
            old.unlink(missing_ok=True)
        self._staged[flag] = Path(tmp)
        return Path(tmp)

    def put(self, flag: str, data: bytes) -> None:
        """Stage the bytes of output ``flag`` (nothing happens for an output not given)."""
        if flag not in self.paths:
            return
        tmp = self.path(flag)
        _write_named(lambda: open(tmp, "wb"), data, self.paths[flag])

    def commit(self) -> list[Path]:
        """Move every staged output into place; on a failure remove what this commit created."""
        done: list[tuple[Path, bool]] = []
        try:
            for flag, tmp in list(self._staged.items()):
                final = self.paths[flag]
                existed = final.exists()
                publish(tmp, final)
                del self._staged[flag]
                done.append((final, existed))
        except BaseException:
            for final, existed in done:
                if not existed:
                    final.unlink(missing_ok=True)
            self.abort()
            raise
        return [f for f, _ in done]

    def abort(self) -> None:
        """Remove the staged temporary files."""
        for tmp in self._staged.values():
            tmp.unlink(missing_ok=True)
        self._staged.clear()

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if isinstance(exc, OSError) and exc.filename is None and self._staged:
            # a writer's "No space left on device" names no file: the output being written
            exc.filename = str(self.paths[list(self._staged)[-1]])
        self.abort()


def png_bytes(rgba: np.ndarray) -> bytes:
    """An ``(h, w, 3|4) uint8`` image as PNG bytes."""
    arr = np.ascontiguousarray(rgba, dtype=np.uint8)
    buf = io.BytesIO()
    Image.fromarray(arr, "RGBA" if arr.shape[-1] == 4 else "RGB").save(buf, format="PNG")
    return buf.getvalue()


def json_bytes(obj) -> bytes:
    """``obj`` as indented JSON (numpy values and paths allowed)."""
    return (json.dumps(obj, indent=2, default=_json_default) + "\n").encode()
