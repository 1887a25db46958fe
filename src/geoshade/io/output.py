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
import shutil
import tempfile
import uuid
from pathlib import Path

import numpy as np
from PIL import Image

from geoshade.errors import InputError


def publish(staged, final) -> Path:
    """Move a finished output ``staged`` into place as ``final``: the one atomic publish.

    A file gets a normal file's mode (``0666`` less the umask) and replaces ``final`` at once
    (:func:`os.replace`: a reader sees the old file or the new one).  A folder (a store) is
    renamed into place; an existing ``final`` is first moved aside under a hidden name and
    removed only after the rename, so a reader never sees half a store (and a failed rename puts
    the old one back).  ``staged`` must be in ``final``'s folder.

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
