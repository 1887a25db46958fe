"""``geoshade serve``: geoshade in a web browser, for data that lives on a server or a cluster.

The pictures are drawn on the server by the parts' own Views (EGL, no display) and streamed to
the page: JPEG while the camera moves, lossless PNG when it rests, frames dropped rather than
queued. The panels are generated from the parts' option declarations
(:mod:`geoshade.viewer.controls`); one GL thread draws for every tab
(:mod:`geoshade.web.engine`); the server (:mod:`geoshade.web.app`, aiohttp) is bound to
127.0.0.1 and refuses requests without the token printed at start; the browser opens only what
the :class:`~geoshade.web.catalog.Catalog` lists. Needs the ``web`` extra (aiohttp, Pillow).

>>> import geoshade.web
>>> callable(geoshade.web.serve)
True
"""

from __future__ import annotations

from geoshade.web.app import serve as run


def serve(*args, **kwargs):
    """:func:`geoshade.web.app.serve` (imported on first use: the ``web`` extra)."""

    return run(*args, **kwargs)


__all__ = ["serve"]
