"""The door of ``geoshade serve``: how many connections it holds, and for how long, before a
client has shown the token.

Anyone who can reach the port can open connections without the token; each holds a file
descriptor. Left alone, ~1,100 half-open connections (a request line and never the end of the
headers) exhaust the process's descriptors, and the user's own tab can no longer connect. The gate
keeps the server usable for whoever holds the token:

- a connection that has not shown the token (a *pending* one) is closed
  :data:`HEADER_S` seconds after it was accepted, whatever it sent;
- at most :data:`MAX_PENDING` pending connections are held: a new one closes the *oldest* pending
  one (a browser sends its request at once, a flood's old connections go first);
- at most :data:`MAX_CONNECTIONS` connections in all (never more than a quarter of the
  descriptors the process may open, see :func:`budget`): beyond it a new connection is closed at
  once, before any work;
- a connection that showed the token (:meth:`Gate.trust`) is kept; aiohttp closes an idle
  keep-alive HTTP connection after :data:`IDLE_S` seconds; a websocket (a tab) lives as long as
  its tab.

>>> Gate(max_connections=8, max_pending=2).limits()
{'connections': 8, 'pending': 2, 'header_s': 10.0}
"""

from __future__ import annotations

import asyncio
import functools
import resource
from collections import OrderedDict
from typing import Any

#: seconds a connection may take to show the token (its request's headers)
HEADER_S = 10.0
#: seconds an idle keep-alive HTTP connection is kept (aiohttp's keepalive_timeout)
IDLE_S = 15.0
#: connections held at most without the token
MAX_PENDING = 64
#: connections held at most in all (capped by :func:`budget`)
MAX_CONNECTIONS = 512
#: descriptors the server keeps for its own files, GL and threads
RESERVED_FDS = 128


def raise_fd_limit(want: int = 4096) -> int:
    """Raise this process's soft limit of open files towards ``want`` (never above the hard
    limit); the soft limit now.

    >>> raise_fd_limit() >= 1
    True
    """
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    target = want if hard == resource.RLIM_INFINITY else min(want, hard)
    if soft != resource.RLIM_INFINITY and soft < target:
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
            soft = target
        except (OSError, ValueError):
            pass
    return soft


def budget(max_connections: int = MAX_CONNECTIONS) -> int:
    """The connections the server holds at most: ``max_connections``, and never more than a
    quarter of the descriptors left after :data:`RESERVED_FDS` (at least 16).

    >>> 16 <= budget() <= MAX_CONNECTIONS
    True
    """
    soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    if soft == resource.RLIM_INFINITY:
        return max_connections
    return max(16, min(max_connections, (soft - RESERVED_FDS) // 4))


class Gate:
    """Counts the server's connections and closes those past the limits (event loop only).

    Parameters
    ----------
    max_connections, max_pending : int
        The limits (see the module).
    header_s : float
        Seconds a pending connection is kept.
    """

    def __init__(self, max_connections: int = MAX_CONNECTIONS, max_pending: int = MAX_PENDING,
                 header_s: float = HEADER_S):
        self.max_connections = max_connections
        self.max_pending = max_pending
        self.header_s = header_s
        #: handler -> transport of every open connection
        self.open: dict[Any, asyncio.Transport] = {}
        #: handler -> the timer that closes it, oldest first (connections without the token)
        self.pending: OrderedDict[Any, asyncio.TimerHandle] = OrderedDict()
        #: connections closed by the gate (all reasons)
        self.closed = 0

    def limits(self) -> dict:
        return {"connections": self.max_connections, "pending": self.max_pending,
                "header_s": self.header_s}

    def admit(self, handler, transport: asyncio.Transport) -> bool:
        """A new connection: False (closed at once) when the server is full of trusted ones."""
        if len(self.pending) >= self.max_pending:
            self._drop(next(iter(self.pending)))          # the oldest pending one goes
        if len(self.open) >= self.max_connections:
            if not self.pending:
                self.closed += 1
                transport.abort()
                return False
            self._drop(next(iter(self.pending)))
        loop = asyncio.get_running_loop()
        self.open[handler] = transport
        self.pending[handler] = loop.call_later(self.header_s, self._expire, handler)
        return True

    def trust(self, handler) -> None:
        """``handler``'s connection showed the token: no longer closed for waiting."""
        timer = self.pending.pop(handler, None)
        if timer is not None:
            timer.cancel()

    def gone(self, handler) -> None:
        self.open.pop(handler, None)
        timer = self.pending.pop(handler, None)
        if timer is not None:
            timer.cancel()

    def _expire(self, handler) -> None:
        if handler in self.pending:
            self._drop(handler)

    def _drop(self, handler) -> None:
        transport = self.open.get(handler)
        self.gone(handler)
        self.closed += 1
        if transport is not None:
            transport.abort()   # no lingering: the descriptor is freed now


@functools.cache
def _classes() -> tuple[type, type]:
    """The gated server and runner, made on first use: aiohttp is the ``web`` extra, and this
    module imports without it (the core install's import check)."""
    from aiohttp import web

    class GatedServer(web.Server):
        """aiohttp's low-level server with a :class:`Gate` at its door."""

        def __init__(self, gate: Gate, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.gate = gate

        def connection_made(self, handler, transport) -> None:
            super().connection_made(handler, transport)
            self.gate.admit(handler, transport)

        def connection_lost(self, handler, exc: BaseException | None = None) -> None:
            self.gate.gone(handler)
            super().connection_lost(handler, exc)

    class GatedRunner(web.AppRunner):
        """An :class:`aiohttp.web.AppRunner` whose server is a ``GatedServer`` (idle
        keep-alive connections closed after :data:`IDLE_S`)."""

        def __init__(self, app, gate: Gate, **kwargs):
            kwargs.setdefault("keepalive_timeout", IDLE_S)
            super().__init__(app, **kwargs)
            self.gate = gate
            self._handler_args = {k: v for k, v in kwargs.items()
                                  if k not in ("handle_signals", "shutdown_timeout")}

        async def _make_server(self) -> web.Server:
            made = await super()._make_server()
            return GatedServer(self.gate, made.request_handler,
                               request_factory=made.request_factory,
                               handler_cancellation=made.handler_cancellation,
                               loop=asyncio.get_running_loop(),
                               access_log_class=self._kwargs["access_log_class"],
                               **self._handler_args)

    return GatedServer, GatedRunner


def GatedRunner(app, gate: Gate, **kwargs):  # noqa: N802 - a class made on first use
    """An :class:`aiohttp.web.AppRunner` whose server is a gated ``aiohttp.web.Server``
    (connections admitted by ``gate``; idle keep-alive connections closed after :data:`IDLE_S`)."""
    return _classes()[1](app, gate, **kwargs)


__all__ = ["HEADER_S", "IDLE_S", "MAX_CONNECTIONS", "MAX_PENDING", "Gate", "GatedRunner",
           "budget", "raise_fd_limit"]
