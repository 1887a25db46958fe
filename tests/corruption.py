"""Helpers of the corruption suites: run a command on a damaged input and check that it failed
cleanly -- a non-zero exit code (not 70, the code of a bug), one ``geoshade: error:`` line that
names the file, no traceback, every input unchanged (by hash) and no new file left behind.

Use ``clean_failure(capsys, argv, inputs=..., watch=...)`` in a test; ``Tally`` counts what a
suite tried and what came out clean (reported in the closing notes).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

#: the exit code of an unexpected exception (a bug): never the answer to bad input
BUG_EXIT = 70


def file_hashes(paths: Iterable) -> dict[str, str]:
    """sha256 of every file under ``paths`` (files or folders)."""
    out = {}
    for p in paths:
        p = Path(p)
        files = [p] if p.is_file() else sorted(q for q in p.rglob("*") if q.is_file()) \
            if p.is_dir() else []
        for f in files:
            out[str(f)] = hashlib.sha256(f.read_bytes()).hexdigest()
    return out


def listing(folders: Iterable) -> set[str]:
    """Every file and folder under ``folders`` (to find outputs left behind)."""
    out: set[str] = set()
    for d in folders:
        d = Path(d)
        if d.is_dir():
            for root, dirs, files in os.walk(d):
                out.update(os.path.join(root, n) for n in dirs + files)
    return out


def run_cli(capsys, argv) -> tuple[int, str, str]:
    from geoshade.cli.main import main

    rc = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def clean_failure(capsys, argv, inputs=(), watch=(), names=None, expect=None,
                  allow_warnings: bool = False) -> str:
    """Run ``geoshade argv`` and assert it failed cleanly; return the error line.

    Parameters
    ----------
    inputs : paths whose content must not change
    watch : folders in which no new file may appear
    names : a string the error line must contain (default: the name of the first input)
    expect : another string the error line must contain
    allow_warnings : other ``geoshade: warning:`` lines may come with the error
    """
    before = file_hashes(inputs)
    seen = listing(watch)
    rc, _out, err = run_cli(capsys, argv)
    assert rc != 0, f"exit 0 for {argv}: {err}"
    assert rc != BUG_EXIT, f"a bug (exit {BUG_EXIT}) for {argv}: {err}"
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("geoshade: error:")]
    others = [ln for ln in lines if not ln.startswith("geoshade: error:")]
    assert len(errors) == 1, err
    if not allow_warnings:
        assert not others, err
    else:
        assert all(ln.startswith("geoshade: warning:") for ln in others), err
    line = errors[0]
    if names is None and inputs:
        names = Path(next(iter(inputs))).name
    if names:
        assert names in line, f"{names!r} not named in: {line}"
    if expect:
        assert expect in line, f"{expect!r} not in: {line}"
    assert file_hashes(inputs) == before, f"an input changed: {argv}"
    new = listing(watch) - seen
    assert not new, f"left behind: {sorted(new)}"
    return line


class Tally:
    """Counts of cases tried and failing cleanly, per suite (printed with ``-s``)."""

    def __init__(self, name: str):
        self.name, self.tried, self.clean = name, 0, 0

    def __call__(self, ok: bool) -> None:
        self.tried += 1
        self.clean += bool(ok)

    def __str__(self) -> str:
        return f"{self.name}: {self.clean} of {self.tried} clean"

    def clean_failure(self, capsys, argv, inputs, watch, **kw) -> str:
        """:func:`clean_failure`, counted in this tally (clean or not)."""
        try:
            line = clean_failure(capsys, argv, inputs=inputs, watch=watch, **kw)
        except AssertionError:
            self(False)
            raise
        self(True)
        return line
