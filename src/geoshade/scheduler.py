"""Where dask work runs: a local scheduler by name, or a ``dask.distributed`` cluster.

``scheduler=`` of every out-of-core function (:mod:`geoshade.compute.lazy`,
:func:`geoshade.io.stores.ingest.ingest`) and ``--scheduler`` of the CLI take:

- ``None`` or ``"threads"``: dask's local threaded scheduler; ``"synchronous"`` and
  ``"processes"`` are dask's other local schedulers (:data:`LOCAL_SCHEDULERS`);
- a ``distributed.Client``: that cluster, used as is (never closed here);
- an address such as ``"tcp://10.0.0.5:8786"``: a client is connected for the work (giving up
  after :data:`CONNECT_TIMEOUT_S` seconds with one clear line) and closed afterwards;
- ``"local:N"``: a ``distributed.LocalCluster`` with ``N`` workers is started on this machine for
  the work and shut down afterwards.

:func:`client_for` makes the client of a cluster, :func:`using_scheduler` yields what
``dask.compute(..., scheduler=...)`` takes and cleans up after the ``with`` block.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from geoshade.errors import InputError, require

#: dask's local schedulers accepted by name
LOCAL_SCHEDULERS = ("threads", "synchronous", "sync", "single-threaded", "processes")
#: seconds to wait for a dask scheduler given by address
CONNECT_TIMEOUT_S = 5
#: prefix of the address form that starts a local cluster: ``"local:4"`` (4 workers)
LOCAL_CLUSTER = "local:"


def is_client(scheduler) -> bool:
    """Whether ``scheduler`` is a ``distributed.Client`` (duck-typed: nothing is imported).

    Examples
    --------
    >>> is_client("threads"), is_client(None)
    (False, False)
    """
    return hasattr(scheduler, "submit") and hasattr(scheduler, "scheduler_info")


def require_cluster(scheduler, distributed: bool, single: str) -> None:
    """One line unless ``scheduler`` names a dask.distributed cluster (an address, ``local:N``
    or a Client) and ``distributed`` is on: the options of a View drawn on a cluster
    (``single``: the View to use for one process).

    >>> require_cluster("threads", True, "CoreView")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler threads: distributed rendering needs a ...
    """
    if not distributed:
        raise InputError(f"distributed: this View draws on a cluster; use {single} (or leave "
                         "out distributed) for one process")
    if scheduler is None or (not is_client(scheduler) and str(scheduler) in LOCAL_SCHEDULERS):
        raise InputError(f"scheduler {scheduler}: distributed rendering needs a "
                         "dask.distributed cluster: an address (tcp://HOST:8786), local:N or a "
                         "distributed.Client")


def _distributed():
    return require("distributed", "distributed", "a dask cluster")


def _workers(name: str) -> int:
    text = name[len(LOCAL_CLUSTER):]
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise InputError(f"scheduler {name}: expected {LOCAL_CLUSTER}N with N >= 1 workers, "
                         f"e.g. {LOCAL_CLUSTER}4")
    return n


def client_for(scheduler, *, processes: bool = True) -> tuple[Any, bool]:
    """``(client, owned)``: a ``distributed.Client`` for ``scheduler`` and whether to close it.

    Parameters
    ----------
    scheduler : distributed.Client or str
        A client (returned as is, ``owned`` False), an address ``tcp://HOST:PORT`` (connected,
        ``owned`` True) or ``"local:N"`` (a new local cluster of N workers, ``owned`` True:
        closing the client shuts the cluster down).
    processes : bool
        ``"local:N"`` only: workers are processes (default) or threads of this process.

    Raises
    ------
    InputError
        One line: a local scheduler name or a malformed ``local:N``, an address no scheduler
        answers within :data:`CONNECT_TIMEOUT_S` seconds; or
        :class:`~geoshade.errors.MissingExtraError` without the ``distributed`` package.

    Examples
    --------
    >>> client, owned = client_for("local:1", processes=False)  # doctest: +SKIP
    >>> len(client.scheduler_info()["workers"]), owned  # doctest: +SKIP
    (1, True)
    >>> client.close()  # doctest: +SKIP
    >>> client_for("threads")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler threads: a local dask scheduler, not a cluster; give \
an address (tcp://HOST:8786), local:N or a distributed.Client
    """
    if is_client(scheduler):
        return scheduler, False
    name = str(scheduler)
    if scheduler is None or name in LOCAL_SCHEDULERS:
        raise InputError(f"scheduler {name}: a local dask scheduler, not a cluster; give an "
                         "address (tcp://HOST:8786), local:N or a distributed.Client")
    if name.startswith(LOCAL_CLUSTER):
        n = _workers(name)
        client = _distributed().Client(n_workers=n, threads_per_worker=1, processes=processes,
                                       dashboard_address=None, silence_logs=40,
                                       set_as_default=False)
        return client, True  # started without an address: closing it closes the cluster
    client_cls = _distributed().Client  # one line when the distributed extra is missing
    _check_address(name)
    try:
        client = client_cls(name, timeout=f"{CONNECT_TIMEOUT_S}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise InputError(
            f"scheduler {name}: unreachable (no dask scheduler answered within "
            f"{CONNECT_TIMEOUT_S} s: {first}); start one with 'dask scheduler' or leave out "
            "--scheduler") from None
    return client, True


def _check_address(name: str) -> None:
    """Refuse a malformed address before a ``Client`` is made (a failed one complains again
    when Python exits).

    >>> _check_address("tcp://127.0.0.1:8786")
    >>> _check_address("junk")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler junk: expected an address such as tcp://HOST:8786 ...
    """
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, loc = parse_address(name)
        if scheme in ("tcp", "tls", "ucx", "ws", "wss"):
            parse_host_port(loc)
    except (ValueError, TypeError) as err:
        raise InputError(f"scheduler {name}: expected an address such as tcp://HOST:8786 (or "
                         f"HOST:8786), or {LOCAL_CLUSTER}N for N local workers ({err})") from None


@contextlib.contextmanager
def using_scheduler(scheduler=None, *, processes: bool = True) -> Iterator[Any]:
    """Yield what ``dask.compute(..., scheduler=...)`` takes for ``scheduler``.

    Parameters
    ----------
    scheduler : None, str or distributed.Client
        None: ``"threads"``; a name in :data:`LOCAL_SCHEDULERS` (yielded as is); otherwise a
        cluster (see :func:`client_for`), whose client is closed after the ``with`` block if it
        was made here.
    processes : bool
        For ``"local:N"`` (see :func:`client_for`).

    Raises
    ------
    InputError
        As :func:`client_for`.

    Examples
    --------
    >>> with using_scheduler() as s:
    ...     s
    'threads'
    >>> with using_scheduler("tcp://127.0.0.1:9") as s:  # doctest: +SKIP
    ...     pass
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler tcp://127.0.0.1:9: unreachable ...
    """
    if scheduler is None:
        yield "threads"
        return
    if not is_client(scheduler) and str(scheduler) in LOCAL_SCHEDULERS:
        yield str(scheduler)
        return
    client, owned = client_for(scheduler, processes=processes)
    try:
        yield client
    finally:
        if owned:
            client.close()
