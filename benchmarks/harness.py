"""Helpers shared by every ``benchmarks/bench_<part>.py`` (process memory, RESULTS.md sections).

Each benchmark puts this folder on ``sys.path`` and imports from here, so the worker processes
(``python bench_<part>.py --worker CONFIG``) find it as well.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path

HEADER = "# geoshade benchmark results\n\nOne section per part, written by `geoshade bench PART`.\n"


def status_kib(field: str, path: str = "/proc/self/status") -> int | None:
    """A ``kB`` field of a /proc status file (``VmHWM``, ``VmRSS``, ``MemAvailable`` ...)."""
    try:
        for line in Path(path).read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1])
    except (OSError, ValueError):
        pass
    return None


def peak_rss_mib() -> float:
    """Peak RSS of this process in MiB: VmHWM (per exec image; ru_maxrss as a fallback).

    ``ru_maxrss`` keeps the parent's high-water mark across a fork + exec on Linux, so VmHWM is
    preferred: it belongs to this process image alone.
    """
    kib = status_kib("VmHWM")
    if kib is None:
        import resource

        kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return kib / 1024.0


def replace_section(text: str, section: str, part: str) -> str:
    """``text`` (RESULTS.md) with the ``part`` section replaced, or appended when it has none.

    >>> replace_section("", "<!-- x:begin -->\\nA\\n<!-- x:end -->\\n", "x").count("\\nA\\n")
    1
    """
    begin, end = f"<!-- {part}:begin -->", f"<!-- {part}:end -->"
    if not text.strip():
        text = HEADER
    b, e = text.find(begin), text.find(end)
    if b != -1 and e > b:
        return text[:b] + section.rstrip("\n") + text[e + len(end):]
    return text.rstrip("\n") + "\n\n" + section


def write_results(out_dir, part: str, section: str, *others) -> Path:
    """Replace ``part``'s section of ``out_dir/RESULTS.md`` (atomically) and give it and the
    ``others`` (outputs written with atomic writes, which leave mkstemp's 0600) the usual umask
    mode. Returns the RESULTS.md path."""
    from geoshade.io.output import atomic_write_bytes

    res_md = Path(out_dir) / "RESULTS.md"
    old = res_md.read_text() if res_md.is_file() else ""
    atomic_write_bytes(res_md, replace_section(old, section, part).encode())
    umask = os.umask(0)
    os.umask(umask)
    for q in (res_md, *others):
        if Path(q).is_file():
            Path(q).chmod(0o666 & ~umask)
    return res_md


def script_main(worker, part: str, argv=None) -> int:
    """The ``__main__`` of a bench script: ``--worker JSON`` runs one config, else usage (2)."""
    import sys

    args = sys.argv[1:] if argv is None else list(argv)
    if len(args) == 2 and args[0] == "--worker":
        return worker(args[1])
    print(f"usage: bench_{part}.py --worker JSON   (run the benchmark with: geoshade bench "
          f"{part})", file=sys.stderr)
    return 2


def run_worker(script, cfg: dict, timeout_s: float, mem_limit: float | None = None,
               keep=("kind",), drop=()) -> dict:
    """Run ``python SCRIPT --worker CFG`` with a time and memory limit; its last JSON line.

    A worker that dies, or is killed at a limit, gives ``{"ok": False, "error": ...}`` with the
    ``keep`` fields of ``cfg``. Adds ``config`` (``cfg`` less ``drop``), ``elapsed_s`` and
    ``load_avg_1min`` (before, after).
    """
    import json
    import os
    import subprocess
    import sys
    import tempfile
    import time

    cmd = [sys.executable, str(Path(script).resolve()), "--worker", json.dumps(cfg)]
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    killed = None
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(cmd, stdout=out, stderr=err, stdin=subprocess.DEVNULL)
        while True:
            try:
                proc.wait(timeout=0.25)
                break
            except subprocess.TimeoutExpired:
                pass
            if time.perf_counter() - t0 > timeout_s:
                killed = f"killed after the {timeout_s:.0f} s time limit"
            elif mem_limit and (status_kib("VmRSS", f"/proc/{proc.pid}/status") or 0) * 1024 \
                    > mem_limit:
                killed = f"killed above the {mem_limit / 2**30:.1f} GiB memory limit"
            if killed:
                proc.kill()  # the worker this function started, by its own handle
                proc.wait()
                break
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode(errors="replace")
        stderr = err.read().decode(errors="replace")
    res = None
    for line in reversed(stdout.splitlines()):
        if line.startswith("{"):
            try:
                res = json.loads(line)
                break
            except json.JSONDecodeError:
                continue
    if res is None:
        tail = (stderr.strip().splitlines() or ["no output"])[-1]
        res = {"ok": False, **{k: cfg.get(k) for k in keep},
               "error": killed or f"worker exited with {proc.returncode}: {tail}",
               "stderr_tail": stderr[-2000:]}
    res["config"] = {k: v for k, v in cfg.items() if k not in drop}
    res["elapsed_s"] = time.perf_counter() - t0
    res["load_avg_1min"] = [load0, os.getloadavg()[0]]
    return res


def json_default(o):
    """JSON for numpy scalars and arrays (and tuples) in worker results."""
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, (np.ndarray, tuple)):
        return np.asarray(o).tolist() if isinstance(o, np.ndarray) else list(o)
    raise TypeError(type(o).__name__)


def worker_main(config_json: str, pick, keep=("kind",)) -> int:
    """Worker side: run ``pick(cfg)(cfg)`` and print exactly one JSON line (errors included)."""
    import json
    import sys
    import time
    import traceback

    cfg = json.loads(config_json)
    t0 = time.perf_counter()
    try:
        out = {"ok": True, **pick(cfg)(cfg)}
    except Exception as exc:  # report, never crash without JSON
        out = {"ok": False, **{k: cfg.get(k) for k in keep},
               "error": f"{type(exc).__name__}: {exc}",
               "traceback": traceback.format_exc(limit=6), "peak_rss_mib": peak_rss_mib()}
    out["wall_s"] = time.perf_counter() - t0
    sys.stdout.write("\n" + json.dumps(out, default=json_default) + "\n")
    sys.stdout.flush()
    return 0


def machine_info() -> dict:
    """CPU model, cores, RAM, GL renderer, date, and versions."""
    import datetime as _dt

    import numpy as np

    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        ram = int(Path("/proc/meminfo").read_text().split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        ram = None
    info = {"cpu": cpu, "cores": os.cpu_count(),
            "cores_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else os.cpu_count(),
            "ram_bytes": ram, "ram_gib": (ram or 0) / 2**30, "python": platform.python_version(),
            "platform": platform.platform(), "numpy": np.__version__,
            "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
            "load_avg": list(os.getloadavg())}
    try:
        from geoshade.render.context import capabilities, get_context

        caps = capabilities(get_context())
        info.update(gl_renderer=caps["renderer"], gl_version=caps["version"],
                    gl_software=caps["software"], gl_caps=caps)
    except Exception as exc:
        info.update(gl_renderer=f"unavailable ({exc})", gl_version=None, gl_software=True)
    try:
        import geoshade

        info["geoshade"] = getattr(geoshade, "__version__", "?")
    except ImportError:
        pass
    return info
