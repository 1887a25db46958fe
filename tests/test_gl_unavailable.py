"""A machine without OpenGL: one clear line from the context factory, gl tests skipped with it.

None of these tests needs OpenGL: each makes context creation fail on purpose.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys
from pathlib import Path

import pytest

from geoshade.errors import GLUnavailableError

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def context_module(monkeypatch):
    """``geoshade.render.context`` with GL switched on again and no shared context made."""
    import geoshade.render.context as context

    monkeypatch.delenv("GEOSHADE_GL", raising=False)
    monkeypatch.delenv("GEOSHADE_GL_BACKEND", raising=False)
    monkeypatch.setattr(context, "_SHARED", None)
    return context


def assert_one_line(err: GLUnavailableError, why: str) -> None:
    text = str(err)
    assert "\n" not in text
    assert text.startswith(f"no OpenGL >= 4.3 context: {why}"), text
    assert "apt-get install" in text  # says how to get it
    assert err.exit_code == 3


def test_geoshade_gl_off_is_the_missing_egl_error(context_module, monkeypatch):
    monkeypatch.setenv("GEOSHADE_GL", "off")
    with pytest.raises(GLUnavailableError) as info:
        context_module.create_context()
    assert_one_line(info.value, "GEOSHADE_GL=off.")
    with pytest.raises(GLUnavailableError):
        context_module.create_context(window=True)
    with pytest.raises(GLUnavailableError):
        context_module.get_context()
    assert context_module._SHARED is None


def test_an_unknown_backend_is_one_line(context_module, monkeypatch):
    monkeypatch.setenv("GEOSHADE_GL_BACKEND", "no-such-backend")
    with pytest.raises(GLUnavailableError) as info:
        context_module.create_context()
    assert_one_line(info.value, "")
    assert "no-such-backend" in str(info.value)


def test_egl_without_its_library_is_one_line(context_module, monkeypatch):
    # a real EGL context creation that cannot load libEGL: what a machine without Mesa's EGL gets
    real = context_module.moderngl.create_context
    missing = functools.partial(real, libegl="libEGL_geoshade_missing.so.1")
    monkeypatch.setattr(context_module.moderngl, "create_context", missing)
    with pytest.raises(GLUnavailableError) as info:
        context_module.create_context()
    assert_one_line(info.value, "")


def _pytest(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    # in this process: -v's lines are read below (a worker's would start with [gw0])
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-p",
                           "no:xdist", "-v", "-rs", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300, env={**os.environ, **(env or {})})


def _outcomes(stdout: str) -> dict[str, str]:
    """nodeid -> PASSED/SKIPPED/FAILED... from ``pytest -v`` lines."""
    out = {}
    for line in stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and "::" in parts[0] and parts[1].isupper():
            out[parts[0]] = parts[1]
    return out


def test_gl_tests_are_skipped_with_one_line_where_gl_is_off():
    # tests using ctx (marked gl automatically), the doctests of a part (some render), a CLI test
    # marked gl explicitly
    proc = _pytest("tests/gl/test_camera_shaders.py", "src/geoshade/core",
                   "tests/cli/test_cli_core.py::test_demo_small", env={"GEOSHADE_GL": "off"})
    assert proc.returncode == 0, proc.stdout[-3000:]
    got = _outcomes(proc.stdout)
    # the camera and preprocessor tests need no GL; the compile error test uses ctx
    assert got["tests/gl/test_camera_shaders.py::test_named_view_directions"] == "PASSED"
    assert got["tests/gl/test_camera_shaders.py::test_compile_error_points_at_file_and_line"
               ] == "SKIPPED"
    assert got["tests/cli/test_cli_core.py::test_demo_small"] == "SKIPPED"
    assert any(k.startswith("src/geoshade/core") and v == "SKIPPED" for k, v in got.items())
    assert "FAILED" not in got.values()
    reasons = [ln for ln in proc.stdout.splitlines() if ln.startswith("SKIPPED [")]
    gl_reasons = [ln for ln in reasons if "OpenGL" in ln]
    assert gl_reasons and all(ln.endswith("no OpenGL >= 4.3 context: GEOSHADE_GL=off")
                              for ln in gl_reasons), gl_reasons


def test_viewer_doctests_are_skipped_with_a_reason_without_pyside6(tmp_path):
    # PySide6 hidden as on a machine without the viewer extra
    (tmp_path / "sitecustomize.py").write_text("import sys\nsys.modules['PySide6'] = None\n")
    path = os.pathsep.join(p for p in (str(tmp_path), os.environ.get("PYTHONPATH")) if p)
    proc = _pytest("src/geoshade/viewer", env={"PYTHONPATH": path})
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert ("the viewer needs PySide6 (pip install 'geoshade[viewer]'): doctests of window.py "
            "not run") in proc.stdout
    assert "error" not in proc.stdout.splitlines()[-1]
