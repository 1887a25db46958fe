"""Shared pytest fixtures: the one headless OpenGL context (``ctx``), real data folder; the
test processes.

A test that uses ``ctx`` is marked ``gl`` automatically and skipped with the reason where no
OpenGL context can be created (the root ``conftest.py`` says how); GL errors fail the test that
made them.

A run of more than one test file (``python -m pytest -q``, a folder, several files) goes to
:data:`WORKERS` processes (pytest-xdist, ``--dist loadfile``: a file's tests run in one process,
in their order, so module fixtures are made once and each file's ``test_zz_counts`` sees its
cases); see :func:`pytest_cmdline_main`. ``-n 0`` or ``-p no:xdist`` runs in this process.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from geoshade.errors import GLUnavailableError

#: the real data sets (``<repo>/../shared/data``); absent on a machine with only the project
SHARED_DATA = (Path(__file__).resolve().parents[1] / ".." / "shared" / "data").resolve()


#: test processes of a run of several files where this machine has as many cores
WORKERS = 2


def _one_file(config) -> bool:
    """Whether the command line names a single test file (or tests of one file)."""
    files = {a.split("::")[0] for a in config.args}
    return len(files) == 1 and Path(config.invocation_params.dir, *files).is_file()


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config):
    """``-n 2 --dist loadfile`` unless the command line says otherwise: no ``-n``, ``--tx`` or
    ``--dist`` of its own, no ``--pdb``, ``-s`` (output shown as it comes), ``--collect-only``,
    not a single file (two workers' start would cost more than they save), not a worker, and
    :data:`WORKERS` cores. (In ``[tool.pytest.ini_options] addopts`` these options would make
    ``-p no:xdist`` a usage error.) A run that collects no test still exits 5."""
    opt = config.option
    if (not config.pluginmanager.hasplugin("xdist") or hasattr(config, "workerinput")
            or opt.numprocesses is not None or opt.tx or opt.dist != "no" or opt.usepdb
            or opt.capture == "no" or opt.collectonly or _one_file(config)
            or len(os.sched_getaffinity(0)) < WORKERS):
        return
    opt.numprocesses, opt.dist = WORKERS, "loadfile"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path of ``<repo>/../shared/data``; skips the test when that folder is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real data folder {SHARED_DATA} is absent (see shared/data/README.md)")
    return SHARED_DATA


@pytest.fixture(scope="session")
def ctx():
    """The process-wide headless context (``geoshade.render.context.get_context``)."""
    from geoshade.render.context import get_context

    try:
        return get_context()
    except GLUnavailableError as err:
        pytest.skip(str(err).split(". ")[0])


@pytest.fixture(autouse=True)
def _gl_error_check(request):
    if "ctx" not in request.fixturenames:
        yield
        return
    context = request.getfixturevalue("ctx")
    _ = context.error  # clear
    yield
    assert context.error == "GL_NO_ERROR", "the test left a GL error"


@pytest.fixture
def shading():
    from geoshade.styles.shading import shading_uniforms

    return shading_uniforms()


@pytest.fixture(autouse=True)
def _bare_renders(monkeypatch):
    """Views render without annotations unless a test asks for them (``annotations=True``):
    the exact-oracle comparisons use the bare render, as ``--no-annotations`` and
    ``annotations=False`` give it. The CLI passes ``annotations`` explicitly, so CLI pictures
    keep theirs."""
    import geoshade.styles.options as options

    monkeypatch.setattr(options, "ANNOTATIONS_DEFAULT", False)
