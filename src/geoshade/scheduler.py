"""Where work runs: this process, a local dask scheduler by name, or a ``dask.distributed``
cluster — one parsed :class:`Scheduler` value, the only thing compute, io and render take for
it, with one meaning everywhere.

``scheduler=`` of every View, out-of-core function (:mod:`geoshade.compute.voxels.lazy`, porosity,
:func:`geoshade.io.stores.ingest.ingest`) and ``--scheduler`` of every CLI command take:

- ``None`` (the default, :data:`HERE`): this process. Arrays in memory are computed in place
  (the numpy slab loops: selection maps, porosity), a dask array (a store) on dask's threads;
  ingest writes its slabs with its own ``workers`` threads;
- ``"threads"``, ``"synchronous"`` (``"sync"``), ``"processes"``: that local dask scheduler,
  for every computation (an array in memory is wrapped as a dask array);
- a ``distributed.Client``: that cluster, used as is (never closed here);
- an address such as ``"tcp://10.0.0.5:8786"``: a client is connected for the work (giving up
  after :data:`CONNECT_TIMEOUT_S` seconds with one clear line) and closed afterwards;
- ``"local:N"``: a ``distributed.LocalCluster`` with ``N`` workers is started on this machine for
  the work and shut down afterwards.

Anything else is refused in one line by :meth:`Scheduler.parse`, the value every option field
that takes a scheduler holds (parsed once, before any GL or data work; nothing turns it back
into text). Where the *drawing* happens is a separate option, ``distributed`` (core, grid): it
needs a cluster here and never changes where the dask work runs. A View owns one
:class:`SchedulerSession`: the cluster of ``local:N`` or an address is started (connected)
once, on first use, and closed by the View's ``release()``.

:func:`client_for` makes the client of a cluster, :func:`using_scheduler` yields what
``dask.compute(..., scheduler=...)`` takes and cleans up after the ``with`` block (a session is
left open: its owner closes it).
"""

from __future__ import annotations

import contextlib
import importlib.util
import ipaddress
import logging
import os
import re
import socket
import ssl
import sys
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
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


def live_workers(client) -> list[str]:
    """The addresses of the workers the scheduler knows now, sorted (asked, never cached).

    ``client.scheduler_info()["workers"]`` is not used: the client refreshes that record every
    few seconds *without* the workers, and a refresh landing between the fetch and the read
    leaves it empty (a cluster of two then reads as "no worker").

    Examples
    --------
    >>> class Two:
    ...     def nthreads(self): return {"tcp://b:2": 1, "tcp://a:1": 1}
    >>> live_workers(Two())
    ['tcp://a:1', 'tcp://b:2']
    """
    return sorted(client.nthreads())


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
    if not Scheduler.parse(scheduler).is_cluster:
        raise InputError(f"scheduler {scheduler}: distributed rendering needs a "
                         "dask.distributed cluster: an address (tcp://HOST:8786), local:N or a "
                         "distributed.Client")


#: dask.distributed's loggers that :func:`quiet_cluster_logs` silences (the ones its import sets
#: a level on, from dask's ``logging`` config; the others follow ``distributed``)
DISTRIBUTED_LOGGERS = ("distributed", "distributed.client", "distributed.gc")
_QUIET_LOGS = {"on": False}


def quiet_cluster_logs() -> None:
    """Silence dask.distributed's loggers in this process, now and again once ``distributed``
    is imported (for a cluster: :func:`client_for`), since its import sets their levels from
    dask's config. The command line calls it: geoshade says in its own line what a cluster
    did, and a comm's "Batched Comm Closed" logged as a cluster of threads shuts down, after
    the cluster handed back the levels it had raised (``silence_logs``), is noise."""
    _QUIET_LOGS["on"] = True
    _apply_quiet_logs()


def _apply_quiet_logs() -> None:
    if _QUIET_LOGS["on"]:
        for name in DISTRIBUTED_LOGGERS:
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _distributed():
    dist = require("distributed", "distributed", "a dask cluster")
    _apply_quiet_logs()   # after the import, which set the levels
    return dist


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


#: seconds a cluster may take to show its first worker before the work is refused in one line
WORKER_TIMEOUT_S = 30
#: what a cluster trusts, for ``--help`` and the messages
TRUST = ("local:N runs its workers with TLS and throw-away certificates (or as threads), no "
         "dashboard; an address is trusted to run code in this process: use tls:// with the "
         "certificates of dask's config (distributed.comm.tls.*)")
#: what ``local:N`` says when ``cryptography`` (the ``distributed`` extra) is absent
THREADED = (f"scheduler {LOCAL_CLUSTER}{{n}}: the workers are threads of this process, not "
            "processes (the TLS certificates of worker processes need the 'cryptography' "
            "package: pip install 'geoshade[distributed]'); each draws with its own OpenGL "
            "context, the same picture")
#: dask config for clusters geoshade starts: no HTTP pages (workers, call stacks, logs)
_NO_HTTP = {"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []}


def _local_cluster(n: int, processes: bool):
    """A LocalCluster of ``n`` workers only this process can use: worker processes talk TLS
    with throw-away certificates (``cryptography`` makes them); without it, threads of this
    process (in-process transport, nothing listens for code), said in one warning
    (:data:`THREADED`). No dashboard, no HTTP routes."""
    import dask

    cores = os.cpu_count() or 1
    if n > cores:  # checked where the cluster starts: parsing does not depend on the machine
        raise InputError(f"scheduler {LOCAL_CLUSTER}{n}: {n} workers on a machine with {cores} "
                         f"cores; give at most {LOCAL_CLUSTER}{cores}")
    dist = _distributed()
    kw: dict[str, Any] = {"n_workers": n, "threads_per_worker": 1, "dashboard_address": None,
                          "silence_logs": 50}
    security = None
    if processes:
        try:
            from distributed.security import Security

            security = Security.temporary()
        except ImportError:  # no `cryptography`: threads, which nobody else can reach
            processes = False
            warnings.warn(THREADED.format(n=n), UserWarning, stacklevel=3)
    if security is not None:
        kw.update(security=security, protocol="tls://", host="127.0.0.1")
    with dask.config.set(_NO_HTTP), warnings.catch_warnings():
        # the route-less HTTP server moves off a busy port 8787: nothing for the user to do
        warnings.filterwarnings("ignore", message=r"Port \d+ is already in use")
        cluster = dist.LocalCluster(processes=processes, **kw)
        try:
            client = dist.Client(cluster, security=security, set_as_default=False)
        except BaseException:
            cluster.close()
            raise
    client._start_arg = None  # as for Client(n_workers=...): closing the client closes the cluster
    return client


def _is_local_host(host: str) -> bool:

    host = host.strip("[]")
    if host in ("localhost", ""):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _remote_security(name: str):
    """The Security of an address: ``tls://`` needs certificates (dask config
    ``distributed.comm.tls.{ca-file,client.cert,client.key}``); plain ``tcp://`` beyond this
    machine is warned about (whoever answers there can run code here)."""
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.security import Security

    scheme, loc = parse_address(name)
    if scheme == "tls":
        security = Security()  # reads dask's config
        if not security.tls_ca_file:
            raise InputError(f"scheduler {name}: tls:// needs certificates: set "
                             "distributed.comm.tls.ca-file, .client.cert and .client.key in "
                             "dask's config (or DASK_DISTRIBUTED__COMM__TLS__CA_FILE, ...)")
        return security
    host = parse_host_port(loc)[0] if scheme in ("tcp", "ws") else ""
    if scheme in ("tcp", "ws") and not _is_local_host(host):
        warnings.warn(f"scheduler {name}: plain {scheme}:// to another machine, without "
                      "authentication: whoever answers at that address can run code in this "
                      "process; use tls:// with certificates", UserWarning, stacklevel=3)
    return None


def _wait_for_worker(client, name: str, owned: bool, timeout: float | None = None) -> None:
    """One line when no worker joins within ``timeout`` seconds (the work would wait
    forever)."""
    timeout = WORKER_TIMEOUT_S if timeout is None else timeout
    try:
        client.wait_for_workers(1, timeout=timeout)
    except (TimeoutError, OSError) as err:
        if owned:
            client.close()
        raise InputError(f"scheduler {name}: no worker joined the cluster within {timeout:g} s "
                         f"({type(err).__name__}); start workers with 'dask worker "
                         f"{name}' or use {LOCAL_CLUSTER}N") from None


def client_for(scheduler, *, processes: bool = True) -> tuple[Any, bool]:
    """``(client, owned)``: a ``distributed.Client`` for ``scheduler`` and whether to close it.

    Parameters
    ----------
    scheduler : Scheduler, SchedulerSession, distributed.Client or str
        A cluster (what :meth:`Scheduler.parse` takes): a client (returned as is, ``owned``
        False), an address ``tcp://HOST:PORT`` (connected, ``owned`` True) or ``"local:N"`` (a
        new local cluster of N workers, ``owned`` True: closing the client shuts the cluster
        down); a session: its client (``owned`` False: its owner closes it).
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
    >>> len(live_workers(client)), owned  # doctest: +SKIP
    (1, True)
    >>> client.close()  # doctest: +SKIP
    >>> client_for("threads")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler threads: a local scheduler, not a cluster; give an \
address (tcp://HOST:8786), local:N or a distributed.Client
    """
    if isinstance(scheduler, SchedulerSession):   # its owner closes the client
        return scheduler.client(), False
    s = Scheduler.parse(scheduler)
    if s.kind == "client":
        return s.client, False
    if s.kind == "local":
        return _local_cluster(s.workers, processes), True  # its client.close() ends it
    if s.kind != "address":
        raise InputError(f"scheduler {s}: a local scheduler, not a cluster; give an "
                         "address (tcp://HOST:8786), local:N or a distributed.Client")
    name = s.address
    client_cls = _distributed().Client  # one line when the distributed extra is missing
    _check_address(name)
    security = _remote_security(name)
    left = _probe(name, security)   # something that is no dask scheduler: one line, in time
    try:
        client = client_cls(name, timeout=f"{left:.3f}s", set_as_default=False,
                            security=security)
    except (OSError, TimeoutError, ValueError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise InputError(
            f"scheduler {name}: unreachable (no dask scheduler answered within "
            f"{CONNECT_TIMEOUT_S} s: {first}); start one with 'dask scheduler' or leave out "
            "--scheduler") from None
    _wait_for_worker(client, name, True)
    return client, True


#: schemes a scheduler's address may use and what each needs beyond ``distributed``
_SCHEME_NEEDS = {"tcp": None, "tls": None, "ws": None, "wss": None,
                 "ucx": ("ucp", "distributed_ucxx", "ucx-py (UCX)")}
#: the most bytes of a scheduler's handshake read by :func:`_probe`
_HANDSHAKE_MAX = 1 << 16


def _unreachable(name: str, why: str) -> InputError:
    return InputError(f"scheduler {name}: unreachable (no dask scheduler answered within "
                      f"{CONNECT_TIMEOUT_S} s: {why}); start one with 'dask scheduler' or leave "
                      "out --scheduler")


def _not_dask(name: str, what: str) -> InputError:
    return InputError(f"scheduler {name}: not a dask scheduler ({what}); give the address "
                      "'dask scheduler' prints (tcp://HOST:8786), or leave out --scheduler")


def _read_handshake(sock, name: str, deadline: float) -> bytes:
    """The first message a dask server sends on a new connection (its handshake: an 8-byte
    length, the frame count and lengths, a msgpack map naming ``compression`` and
    ``pickle-protocol``), read by ``deadline``; one line for anything else."""
    data = b""
    need = 8
    while len(data) < need:
        left = deadline - time.monotonic()
        if left <= 0:
            raise _not_dask(name, f"the service there sent nothing within {CONNECT_TIMEOUT_S} "
                                  "s (a dask scheduler speaks first: an HTTP server or "
                                  "another service waits)" if not data else
                                  f"it sent {len(data)} bytes and stopped")
        sock.settimeout(left)
        try:
            chunk = sock.recv(min(65536, need - len(data)))
        except TimeoutError:
            continue
        except OSError as err:
            raise _unreachable(name, err.strerror or type(err).__name__) from None
        if not chunk:
            raise _not_dask(name, "the service there closed the connection without a dask "
                                  "handshake")
        data += chunk
        if len(data) >= 8 and need == 8:
            size = int.from_bytes(data[:8], "little")
            if not 16 <= size <= _HANDSHAKE_MAX:
                shown = data[:40].decode("ascii", "replace").strip()
                raise _not_dask(name, f"the service there answered {shown!r}")
            need = 8 + size
    if b"compression" not in data or b"pickle-protocol" not in data:
        raise _not_dask(name, "the service there answered with no dask handshake")
    return data


def _probe(name: str, security) -> float:
    """Refuse in one line, within :data:`CONNECT_TIMEOUT_S`, an address where no dask
    scheduler answers: closed, silent (an HTTP server), or a service that speaks something
    else first; a scheme whose transport is not installed (``ucx://``). A dask server speaks
    first: its handshake is read and sent back (the scheduler sees a client that connected and
    left). Returns the seconds left of the time-out for the client's own connection.

    >>> _probe("tcp://127.0.0.1:1", None)
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler tcp://127.0.0.1:1: unreachable (no dask scheduler ...
    """
    from distributed.comm.addressing import parse_address, parse_host_port

    t0 = time.monotonic()
    scheme, loc = parse_address(name)
    if scheme not in _SCHEME_NEEDS:
        raise InputError(f"scheduler {name}: the {scheme}:// protocol is not one a scheduler "
                         f"address may use; expected {', '.join(f'{k}://' for k in _SCHEME_NEEDS)}")
    needs = _SCHEME_NEEDS[scheme]
    if needs is not None and not any(importlib.util.find_spec(m) for m in needs[:-1]):
        raise InputError(f"scheduler {name}: {scheme}:// needs {needs[-1]}, which is not "
                         "installed; use tcp:// or tls://")
    if scheme not in ("tcp", "tls"):
        return float(CONNECT_TIMEOUT_S)
    host, port = parse_host_port(loc)
    deadline = t0 + CONNECT_TIMEOUT_S
    try:
        sock = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
    except OSError as err:
        raise _unreachable(name, err.strerror or str(err) or type(err).__name__) from None
    try:
        if scheme == "tls":
            ctx = security.get_connection_args("client")["ssl_context"]
            sock.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                sock = ctx.wrap_socket(sock, server_hostname=host if ctx.check_hostname
                                       else None)
            except (ssl.SSLError, OSError) as err:
                raise _not_dask(name, f"no TLS handshake with dask's certificates "
                                      f"({type(err).__name__}: {err})"[:300]) from None
        data = _read_handshake(sock, name, deadline)
        with contextlib.suppress(OSError):
            sock.settimeout(1)
            sock.sendall(data)   # our handshake: the server's own, so it sees a clean client
    finally:
        with contextlib.suppress(OSError):
            sock.close()
    return max(1.0, CONNECT_TIMEOUT_S - (time.monotonic() - t0))


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


def dask_get(scheduler: Any = "threads") -> Any:
    """What to pass ``dask.compute(..., scheduler=)`` for ``scheduler`` (what
    :func:`using_scheduler` yields): a local scheduler's name becomes dask's function for it,
    and ``None`` (dask's default for arrays) the threaded one while no ``distributed.Client``
    can exist (``distributed`` not imported, no ``scheduler`` in dask's config); a client or
    anything else is returned as it is.

    The same schedulers as dask's names: dask looks a name up only after importing
    ``distributed`` to look for a client (0.4 s, the first time, where the extra is installed),
    which a named local scheduler then ignores.

    Examples
    --------
    >>> import dask
    >>> dask_get("synchronous") is dask.local.get_sync, dask_get("threads") is dask.threaded.get
    (True, True)
    >>> dask_get(None) in (None, dask.threaded.get)
    True
    """
    import dask
    from dask.base import named_schedulers

    if isinstance(scheduler, str):
        return named_schedulers.get(scheduler.lower(), scheduler)
    if scheduler is None and "distributed" not in sys.modules \
            and not dask.config.get("scheduler", None):
        return named_schedulers["threads"]
    return scheduler


@contextlib.contextmanager
def using_scheduler(scheduler=None, *, processes: bool = True) -> Iterator[Any]:
    """Yield what ``dask.compute(..., scheduler=...)`` takes for ``scheduler``.

    Parameters
    ----------
    scheduler : Scheduler, SchedulerSession, or what :meth:`Scheduler.parse` takes
        A session: its :meth:`SchedulerSession.dask` (the session's owner closes it); a local
        scheduler: its dask name (:attr:`Scheduler.dask`; :data:`HERE`, the default:
        ``"threads"``); a cluster: its client (see :func:`client_for`), closed after the
        ``with`` block if it was made here.
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
    if isinstance(scheduler, SchedulerSession):   # its owner keeps the cluster up
        yield scheduler.dask()
        return
    s = Scheduler.parse(scheduler)
    if not s.is_cluster:
        yield s.dask
        return
    client, owned = client_for(s, processes=processes)
    try:
        yield client
    finally:
        if owned:
            client.close()


# --------------------------------------------------------------------------------------------
# the parsed value and its owner
# --------------------------------------------------------------------------------------------
#: the local names :meth:`Scheduler.parse` takes, and the dask scheduler each means
_LOCAL_NAMES = {"threads": "threads", "sync": "synchronous", "synchronous": "synchronous",
                "single-threaded": "synchronous", "processes": "processes"}
#: an address of a dask scheduler: ``[scheme://]host:port`` (IPv6 hosts in brackets)
_ADDRESS = re.compile(r"^(?:(?P<scheme>tcp|tls|ucx|ws|wss)://)?"
                      r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_][A-Za-z0-9_.\-]*):"
                      r"(?P<port>\d{1,5})$")
#: what :meth:`Scheduler.parse` accepts, in its refusal
ACCEPTED = ("threads, sync, processes, local:N (N local workers), an address such as "
            "tcp://HOST:8786, or a distributed.Client")


@dataclass(frozen=True)
class Scheduler:
    """Where work runs, parsed once (:meth:`parse`); nothing is started or connected here.

    kind:    ``"here"`` (the default: this process, arrays in memory computed in place, dask
             arrays on dask's threads), ``"threads"``, ``"synchronous"``, ``"processes"``
             (dask's local schedulers, for every computation), ``"local"`` (a LocalCluster of
             ``workers`` workers, started by its owner), ``"address"`` (a running scheduler at
             ``address``) or ``"client"`` (``client``, a live ``distributed.Client``, used as is
             and never closed here)

    Examples
    --------
    >>> Scheduler.parse(None), Scheduler.parse("sync").kind, Scheduler.parse("local:4").workers
    (Scheduler('here'), 'synchronous', 4)
    >>> Scheduler.parse(None).in_place, Scheduler.parse("threads").in_place
    (True, False)
    >>> Scheduler.parse("tcp://10.0.0.5:8786").is_cluster
    True
    >>> Scheduler.parse("banana")
    Traceback (most recent call last):
    ...
    geoshade.errors.InputError: scheduler 'banana': expected threads, sync, processes, ...
    """

    kind: str
    address: str = ""
    workers: int = 0
    client: Any = None

    @classmethod
    def parse(cls, value, what: str = "scheduler") -> Scheduler:
        """The :class:`Scheduler` of ``value``: None (:data:`HERE`), a local name
        (``"threads"``, ``"sync"``, ``"synchronous"``, ``"single-threaded"``,
        ``"processes"``), ``"local:N"``, an address ``[tcp://]HOST:PORT``, a
        ``distributed.Client``, a :class:`Scheduler` (returned as is) or a
        :class:`SchedulerSession` (its scheduler).

        Raises
        ------
        InputError
            One line naming ``what`` and what it takes, for anything else (before any GL or
            data work: nothing is imported, started or connected).
        """
        if isinstance(value, Scheduler):
            return value
        if isinstance(value, SchedulerSession):
            return value.scheduler
        if value is None:
            return HERE
        if is_client(value):
            return cls("client", client=value)
        if isinstance(value, str):
            name = value.strip()
            if name.lower() in _LOCAL_NAMES:
                return cls(_LOCAL_NAMES[name.lower()])
            if name.lower().startswith(LOCAL_CLUSTER):
                return cls("local", workers=_workers(name))
            if _ADDRESS.match(name) and int(_ADDRESS.match(name)["port"]) < 65536:
                return cls("address", address=name)
        raise InputError(f"{what} {value!r}: expected {ACCEPTED}")

    @property
    def is_cluster(self) -> bool:
        """True for a dask.distributed cluster (``local:N``, an address, a client)."""
        return self.kind in ("local", "address", "client")

    @property
    def in_place(self) -> bool:
        """True for :data:`HERE`: arrays in memory are computed by this process's own loops,
        not as dask graphs."""
        return self.kind == "here"

    @property
    def dask(self) -> str | None:
        """The dask local scheduler ``dask.compute(scheduler=...)`` takes (``"threads"`` for
        :data:`HERE`); None for a cluster (its client is)."""
        return None if self.is_cluster else ("threads" if self.kind == "here" else self.kind)

    def __str__(self) -> str:
        if self.kind == "client":
            return "distributed.Client"
        if self.kind == "local":
            return f"{LOCAL_CLUSTER}{self.workers}"
        return self.address or self.kind

    def __repr__(self) -> str:
        return f"Scheduler({str(self)!r})"


#: this process (the default, ``scheduler=None``): see :class:`Scheduler`
HERE = Scheduler("here")
#: dask's threaded and synchronous schedulers (a worker's own tasks, a dask array's slabs)
THREADS = Scheduler("threads")
SYNCHRONOUS = Scheduler("synchronous")


class SchedulerSession:
    """A :class:`Scheduler` in use by one owner (a View, an ingest): a cluster's client is
    made once, on first use (:meth:`client`), and closed by :meth:`close` when it was made
    here (a LocalCluster of ``local:N`` shuts down with it; a client given stays open).

    :func:`using_scheduler` and every ``scheduler=`` that goes through it take a session:
    the work runs on its cluster, which stays up for the next call.

    Examples
    --------
    >>> s = SchedulerSession(None)
    >>> s.scheduler, s.dask(), s.starts
    (Scheduler('here'), 'threads', 0)
    >>> s.close()
    """

    def __init__(self, scheduler=None, *, processes: bool = True):
        self.scheduler = Scheduler.parse(scheduler)
        self.processes = processes
        self._client: Any = None
        self._owned = False
        #: how many clients (clusters, for ``local:N``) this session made
        self.starts = 0

    @property
    def started(self) -> bool:
        """True while this session holds a client."""
        return self._client is not None

    def client(self):
        """The cluster's ``distributed.Client`` (connected or started on first use)."""
        if self._client is None:
            self._client, self._owned = client_for(self.scheduler, processes=self.processes)
            self.starts += int(self._owned)
        return self._client

    def dask(self):
        """What ``dask.compute(..., scheduler=...)`` takes: a local name, or the client."""
        return self.client() if self.scheduler.is_cluster else self.scheduler.dask

    def close(self) -> None:
        """Close the client made here (idempotent; a client given is left open)."""
        client, owned = self._client, self._owned
        self._client, self._owned = None, False
        if client is not None and owned:
            client.close()

    def __repr__(self) -> str:
        return f"SchedulerSession({self.scheduler}, started={self.started})"


def checked(scheduler):
    """What a ``scheduler=`` argument holds once checked: a :class:`SchedulerSession` as is (its
    owner's cluster), else :meth:`Scheduler.parse`'s value (None: :data:`HERE`; one line for
    anything else, before any work).

    >>> checked(None), checked("sync")
    (Scheduler('here'), Scheduler('synchronous'))
    """
    if isinstance(scheduler, SchedulerSession):
        return scheduler
    return Scheduler.parse(scheduler)


__all__ = ["ACCEPTED", "CONNECT_TIMEOUT_S", "HERE", "LOCAL_CLUSTER", "LOCAL_SCHEDULERS",
           "SYNCHRONOUS", "THREADS", "TRUST", "WORKER_TIMEOUT_S", "Scheduler",
           "SchedulerSession", "checked", "client_for", "is_client", "live_workers",
           "require_cluster", "using_scheduler"]
