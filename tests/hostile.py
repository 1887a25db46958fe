"""The harness of the hostile-input tests (``tests/test_hostile_*.py``, issue 25).

Each case runs the real ``geoshade`` command in a child process (or a small script), in a
folder of its own, and is *clean* when:

- it ended with the expected exit status and, for a refusal, exactly one ``geoshade: error:``
  line on stderr (nothing else but ``geoshade: warning:`` lines, no traceback, no escape
  character);
- every file outside the outputs is unchanged (SHA-256 of each file, the target of each link)
  and no file appeared but the outputs (a planted "marker" would show here);
- the child's peak resident memory (its ``VmHWM``, polled while it runs; ``wait4``'s
  ``ru_maxrss`` only where it ended too soon: that one also counts the test process's pages
  forked before the exec) stayed within its budget.

:func:`record` keeps the outcome per class, so each file's last test prints the tried / clean
table and fails unless every case was clean.
"""

from __future__ import annotations

import hashlib
import os
import resource
import signal
import subprocess
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path

#: class -> list of (case, clean, why or a note such as the peak memory)
RESULTS: dict[str, list[tuple[str, bool, str]]] = {}


@dataclass
class Run:
    rc: int
    out: str
    err: str
    maxrss_mb: float
    timed_out: bool = False
    lines: list[str] = field(default_factory=list)


def run(argv, cwd, *, timeout: float = 120, rlimit_as: int | None = None, stdout=None,
        env: dict | None = None, on_start=None) -> Run:
    """Run ``argv`` (a list; ``["geoshade", ...]`` runs this tree's CLI) in ``cwd``; its exit
    status, stdout, stderr and peak RSS."""
    if argv and argv[0] == "geoshade":
        argv = [sys.executable, "-m", "geoshade.cli.main", *argv[1:]]

    def limits():
        if rlimit_as is not None:
            resource.setrlimit(resource.RLIMIT_AS, (rlimit_as, rlimit_as))

    full_env = {**os.environ, "PYTHONWARNINGS": "ignore::DeprecationWarning", **(env or {})}
    proc = subprocess.Popen([str(a) for a in argv], cwd=cwd, env=full_env,
                            stdout=subprocess.PIPE if stdout is None else stdout,
                            stderr=subprocess.PIPE, preexec_fn=limits)
    chunks: dict[str, bytes] = {"out": b"", "err": b""}

    def drain(name, pipe):
        if pipe is not None:
            chunks[name] = pipe.read()

    hwm: list[int] = [0]   # the child's own peak (VmHWM, kB): wait4's ru_maxrss also counts
    done = threading.Event()  # the forked test process's pages before the exec

    def watch():
        status = f"/proc/{proc.pid}/status"
        while not done.is_set():
            try:
                with open(status) as fh:
                    for line in fh:
                        if line.startswith("VmHWM:"):
                            hwm[0] = max(hwm[0], int(line.split()[1]))
            except (OSError, ValueError):
                pass
            done.wait(0.02)

    threads = [threading.Thread(target=drain, args=("out", proc.stdout)),
               threading.Thread(target=drain, args=("err", proc.stderr)),
               threading.Thread(target=watch, daemon=True)]
    for t in threads:
        t.start()
    killed = []
    timer = threading.Timer(timeout, lambda: (killed.append(1), os.kill(proc.pid, 9)))
    timer.start()
    try:
        if on_start is not None:
            on_start(proc)
        _, status, ru = os.wait4(proc.pid, 0)
    finally:
        timer.cancel()
        done.set()
    proc.returncode = os.waitstatus_to_exitcode(status)
    for t in threads:
        t.join()
    err = chunks["err"].decode("utf-8", "replace")
    return Run(proc.returncode, chunks["out"].decode("utf-8", "replace"), err,
               (hwm[0] or ru.ru_maxrss) / 1024, bool(killed),
               [ln for ln in err.splitlines() if ln.strip()])


def snapshot(folder: Path, *extra: Path) -> dict[str, str]:
    """SHA-256 of every file under ``folder`` (and of ``extra`` files), links by their target
    text: what must not change."""
    out = {}
    paths = [p for p in sorted(Path(folder).rglob("*"))] + [Path(e) for e in extra]
    for p in paths:
        if p.is_symlink():
            out[str(p)] = "link->" + os.readlink(p)
        elif p.is_file() and not _special(p):
            out[str(p)] = hashlib.sha256(p.read_bytes()).hexdigest()
        elif p.exists():
            out[str(p)] = "dir" if p.is_dir() else "special"
    return out


def _special(p: Path) -> bool:
    import stat

    return not stat.S_ISREG(p.lstat().st_mode)


def changed(before: dict, after: dict, outputs=()) -> list[str]:
    """Paths that changed, vanished or appeared, except ``outputs`` (and what is under them)."""
    outs = [str(o) for o in outputs]

    def allowed(p):
        return any(p == o or p.startswith(o + os.sep) or p.startswith(o + ".") for o in outs)

    keys = set(before) | set(after)
    return sorted(k for k in keys if before.get(k) != after.get(k) and not allowed(k))


def one_error_line(r: Run, *needles: str) -> str:
    """'' when stderr is one ``geoshade: error:`` line (plus warnings) holding every needle;
    else why not."""
    errors = [ln for ln in r.lines if ln.startswith("geoshade: error:")]
    other = [ln for ln in r.lines if not ln.startswith("geoshade: ")]
    if r.timed_out:
        return "timed out"
    if "Traceback" in r.err or other:
        return f"noise on stderr: {(other or ['Traceback'])[0][:200]!r}"
    if "\x1b" in r.err:
        return "an escape character reached stderr"
    if len(errors) != 1:
        return f"{len(errors)} error lines: {r.lines[:3]!r}"
    missing = [n for n in needles if n not in errors[0]]
    return f"{errors[0]!r} lacks {missing!r}" if missing else ""


def record(cls: str, case: str, why: str, run_: Run | None = None) -> None:
    """Keep one case's outcome (``why`` empty: clean) and fail the test when it is not."""
    note = why or (f"exit {run_.rc}, peak {run_.maxrss_mb:.0f} MB" if run_ is not None else "")
    RESULTS.setdefault(cls, []).append((case, not why, note))
    assert not why, f"{cls} / {case}: {why}"


def summary(cls: str) -> str:
    """``CLASS: N tried, M clean`` and a line per case."""
    rows = RESULTS.get(cls, [])
    clean = sum(1 for _, ok, _ in rows if ok)
    lines = [f"{cls}: {len(rows)} tried, {clean} clean"]
    lines += [f"    {'clean' if ok else 'NOT CLEAN'}  {case}  {note}" for case, ok, note in rows]
    return "\n".join(lines)


def interrupt_when(path: Path, timeout: float = 60):
    """An ``on_start`` for :func:`run`: SIGINT to the child once ``path`` exists."""
    import time

    def go(proc):
        t0 = time.monotonic()
        while not path.exists() and time.monotonic() - t0 < timeout:
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGINT)  # not Popen.send_signal: it would reap the child
    return go
