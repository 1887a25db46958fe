"""pytest for the whole repository: ``tests/`` and the doctests of ``src/geoshade`` (run by
``--doctest-modules``, see ``[tool.pytest.ini_options]`` in pyproject.toml).

The ``gl`` marker says that a test needs an OpenGL >= 4.3 context:

- it is added automatically to every test that uses the ``ctx`` fixture (``tests/conftest.py``);
- tests that render without that fixture (the CLI render commands, the viewer, a part's
  ``render``) carry it explicitly (``pytestmark = pytest.mark.gl`` or ``@pytest.mark.gl``);
- a doctest of ``src/geoshade`` carries it when one of its examples that is not ``+SKIP`` matches
  :data:`GL_DOCTEST`: it calls ``render(``, ``draw(``, ``view(``, ``open_view(``, ``animate(``,
  ``get_context(`` or ``create_context(``, builds a ``...View(`` or names ``ctx``.

Every ``gl`` test is skipped with one line when no context can be created here; that is tried
once per session, at the first ``gl`` test (so ``-m "not gl"`` never touches OpenGL).
``GEOSHADE_GL=off`` makes context creation fail as on a machine without EGL: CI runs
``GEOSHADE_GL=off python -m pytest -q -m "not gl"`` to prove the rest needs no GL: every
bad option is refused before a View asks for a context (issue 11).

The suite runs in parallel processes (pytest-xdist, ``-n auto --dist loadfile``: a test file's
tests in one process, so its module fixtures are made once); ``-n auto`` is one process per CPU
this process may use, at most one per :data:`GIB_PER_WORKER` GiB of available memory
(:func:`pytest_xdist_auto_num_workers`).

The viewer's modules import PySide6 (the ``viewer`` extra); where it is missing their doctests
are skipped with that reason instead of failing to import.
"""

from __future__ import annotations

import doctest
import importlib.util
import os
import re

import pytest

#: a doctest example that matches this needs an OpenGL context
GL_DOCTEST = re.compile(r"\b(render|draw|view|open_view|animate|get_context|create_context)\(|"
                        r"View\(|\bctx\b")

_GL: dict[str, str | None] = {}

#: memory one test process may take at its peak (the largest cases, llvmpipe's framebuffers)
GIB_PER_WORKER = 4


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: the CPUs this process may use (its affinity, not the machine's count), at
    most one worker per :data:`GIB_PER_WORKER` GiB of available memory, at least one."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    try:
        import psutil

        by_memory = psutil.virtual_memory().available // (GIB_PER_WORKER << 30)
    except ImportError:
        by_memory = cpus or 1
    return max(1, min(cpus or 1, int(by_memory)))


def gl_skip_reason() -> str | None:
    """None when an OpenGL context can be created here, else the one-line reason (cached)."""
    if "reason" not in _GL:
        from geoshade.errors import GLUnavailableError
        from geoshade.render.context import get_context

        try:
            get_context()
            _GL["reason"] = None
        except GLUnavailableError as err:
            _GL["reason"] = str(err).split(". ")[0]  # "no OpenGL >= 4.3 context: <why>"
    return _GL["reason"]


def _doctest_needs_gl(item) -> bool:
    test = getattr(item, "dtest", None)
    if test is None:
        return False
    return any(GL_DOCTEST.search(ex.source) for ex in test.examples
               if not ex.options.get(doctest.SKIP))


def pytest_collection_modifyitems(config, items):
    for item in items:
        if "ctx" in getattr(item, "fixturenames", ()) or _doctest_needs_gl(item):
            item.add_marker(pytest.mark.gl)


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    if item.get_closest_marker("gl") is not None:
        reason = gl_skip_reason()
        if reason is not None:
            pytest.skip(reason)


class _SkippedModule(pytest.File):
    """A module whose doctests cannot be collected here, reported as skipped with the reason."""

    reason = ""

    def collect(self):
        pytest.skip(self.reason)


#: a module that imports PySide6 at its top level (the viewer's Qt modules)
_IMPORTS_QT = re.compile(r"^(from|import) PySide6\b", re.MULTILINE)


@pytest.hookimpl(wrapper=True)
def pytest_collect_file(file_path, parent):
    collectors = yield
    if ("viewer" in file_path.parts and file_path.suffix == ".py"
            and any(type(c).__name__ == "DoctestModule" for c in collectors)
            and importlib.util.find_spec("PySide6") is None
            and _IMPORTS_QT.search(file_path.read_text(encoding="utf-8"))):
        skipped = _SkippedModule.from_parent(parent, path=file_path)
        skipped.reason = ("the viewer needs PySide6 (pip install 'geoshade[viewer]'): doctests "
                          f"of {file_path.name} not run")
        return [c for c in collectors if type(c).__name__ != "DoctestModule"] + [skipped]
    return collectors
