"""Helpers shared by every ``benchmarks/bench_<part>.py`` (process memory, RESULTS.md sections).

Each benchmark puts this folder on ``sys.path`` and imports from here, so the worker processes
(``python bench_<part>.py --worker CONFIG``) find it as well.
"""

from __future__ import annotations

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

    >>> replace_section("", "<!-- x:begin -->\\nA\\n<!-- x:end -->\\n", "x").count("A")
    1
    """
    begin, end = f"<!-- {part}:begin -->", f"<!-- {part}:end -->"
    if not text.strip():
        text = HEADER
    b, e = text.find(begin), text.find(end)
    if b != -1 and e > b:
        return text[:b] + section.rstrip("\n") + text[e + len(end):]
    return text.rstrip("\n") + "\n\n" + section
