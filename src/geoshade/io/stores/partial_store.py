"""The progress file of an unfinished store and disk-full errors, shared by the volume ingest
(:mod:`geoshade.io.stores.ingest`) and the grid store (:mod:`geoshade.io.stores.grid_store`).

``STORE.zarr.partial.progress.json`` (written atomically) records the slabs written so far with
their CRC-32, so that running the same ingest again resumes; a full disk (``ENOSPC``/``EDQUOT``)
anywhere in an exception's chain is found by :func:`_disk_error`.
"""

from __future__ import annotations

import errno
import json
from pathlib import Path

from geoshade.io.output import atomic_write_bytes
from geoshade.io.output import publish as publish_output
from geoshade.io.stores.ingest_lock import refuse_link

#: suffix of the progress file next to a partial store (``CORE.zarr.partial.progress.json``)
PROGRESS_FILE = ".progress.json"


def _disk_error(err: BaseException) -> OSError | None:
    """The ENOSPC/EDQUOT OSError in ``err``'s chain, if any."""
    seen = 0
    e: BaseException | None = err
    while e is not None and seen < 10:
        if isinstance(e, OSError) and e.errno in (errno.ENOSPC, errno.EDQUOT):
            return e
        e = e.__cause__ or e.__context__
        seen += 1
    return None


def refuse_planted(partial: Path) -> None:
    """Refuse a ``*.partial`` store or its progress file that is a symbolic link (planted by
    someone who can write in the output's folder): one line naming it, nothing followed."""
    refuse_link(partial, "unfinished store")
    refuse_link(_progress_path(partial), "ingest progress file")


def _progress_path(partial: Path) -> Path:
    """The progress file, beside the partial store (zarr warns about foreign files inside)."""
    return partial.with_name(partial.name + PROGRESS_FILE)


def _save_progress(partial: Path, state: dict) -> None:
    atomic_write_bytes(_progress_path(partial), json.dumps(state).encode())


def _load_progress(partial: Path) -> dict | None:
    f = _progress_path(partial)
    if not f.is_file():
        return None
    try:
        return json.loads(f.read_text())
    except (OSError, json.JSONDecodeError):
        return None


def publish(partial: Path, out: Path) -> None:
    """Rename the finished ``partial`` store to ``out`` (:func:`geoshade.io.output.publish`, the
    one atomic publish: an existing ``out``, an ``--overwrite``, is moved aside first and removed
    only after the rename, so a reader never sees a half store)."""
    publish_output(partial, out)
