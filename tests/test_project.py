"""Project habits: one version source, the licence and dependency list, changelog, pre-commit."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

import geoshade
from geoshade.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def _requirement_names() -> set[str]:
    meta = PYPROJECT["project"]
    reqs = list(meta["dependencies"]) + PYPROJECT["build-system"]["requires"]
    for extra in meta["optional-dependencies"].values():
        reqs += extra
    names = {re.match(r"[A-Za-z0-9_.\-]+", r).group(0) for r in reqs}
    return {n for n in names if n.lower() != "geoshade"}


def test_version_has_one_source():
    assert "version" not in PYPROJECT["project"]
    assert PYPROJECT["project"]["dynamic"] == ["version"]
    assert PYPROJECT["tool"]["setuptools"]["dynamic"]["version"] == {
        "attr": "geoshade.__version__"}
    assert re.fullmatch(r"\d+\.\d+\.\d+(\.dev\d+|rc\d+)?", geoshade.__version__)


def test_cli_prints_the_version(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"geoshade {geoshade.__version__}"


def test_licence_is_mit_as_declared():
    assert PYPROJECT["project"]["license"] == {"text": "MIT"}
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License") and "2026 the geoshade authors" in text


def test_every_dependency_has_a_licence_row():
    doc = (ROOT / "docs" / "DEPENDENCIES.md").read_text()
    rows = {line.split("|")[1].strip().lower() for line in doc.splitlines()
            if line.startswith("| ") and not line.startswith("| package")}
    missing = sorted(n for n in _requirement_names() if n.lower() not in rows)
    assert not missing, f"docs/DEPENDENCIES.md has no row for {missing}"


def test_changelog_has_unreleased_and_the_current_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert "\n## [Unreleased]\n" in text
    assert f"\n## [{geoshade.__version__}]" in text


def test_pre_commit_runs_ruff_and_the_hygiene_hooks():
    yaml = pytest.importorskip("yaml")
    cfg = yaml.safe_load((ROOT / ".pre-commit-config.yaml").read_text())
    hooks = {h["id"] for repo in cfg["repos"] for h in repo["hooks"]}
    assert {"ruff-check", "trailing-whitespace", "end-of-file-fixer", "check-yaml",
            "check-toml"} <= hooks


def test_readme_set_up_is_two_commands_and_ci_runs_the_second():
    text = (ROOT / "README.md").read_text()
    setup = text.split("\n## Set up\n", 1)[1].split("\n## ", 1)[0]
    blocks = [b.split("```", 1)[0].strip() for b in setup.split("```bash\n")[1:]]
    assert blocks == ["python -m pip install -e . && geoshade demo",
                      'python -m pip install -e ".[test,viewer]" && '
                      'python -m pytest -q -n auto --dist loadfile']
    assert blocks[1] in (ROOT / ".ci" / "run").read_text().splitlines()


def test_exit_codes_are_unique_per_kind_of_failure():
    """Each error class that sets its own exit code has a code no other kind uses, every code
    is in the one table (geoshade.errors.EXIT_CODES) that ``geoshade --help`` prints."""
    import importlib
    import pkgutil

    import geoshade
    from geoshade.errors import EXIT_CODES, GeoshadeError, exit_codes_text

    for m in pkgutil.walk_packages(geoshade.__path__, "geoshade."):
        if m.name.startswith(("geoshade.viewer", "geoshade.napari")):
            continue  # optional extras; their errors are imported below where they install
        importlib.import_module(m.name)
    importlib.import_module("geoshade.viewer.app")
    seen: dict[int, str] = {}

    def walk(cls):
        for sub in cls.__subclasses__():
            yield sub
            yield from walk(sub)

    for cls in walk(GeoshadeError):
        if "exit_code" in vars(cls):
            assert cls.exit_code in EXIT_CODES.values(), cls
            assert cls.exit_code not in seen, (cls.__name__, seen[cls.exit_code])
            seen[cls.exit_code] = cls.__name__
    assert len(set(EXIT_CODES.values())) == len(EXIT_CODES)
    assert len(seen) >= 8
    assert " 70  a bug" in exit_codes_text()


def test_one_atomic_publish():
    """Every output (file or store) reaches its final name through geoshade.io.output.publish:
    no other module renames or replaces files."""
    import pathlib
    import re

    src = pathlib.Path(__file__).resolve().parents[1] / "src" / "geoshade"
    pattern = re.compile(r"\bos\.(replace|rename|renames)\(|shutil\.move\(")
    found = [f"{p.relative_to(src)}:{n}" for p in sorted(src.rglob("*.py"))
             if p.name != "output.py" or p.parent.name != "io"
             for n, line in enumerate(p.read_text().splitlines(), 1) if pattern.search(line)]
    assert not found, found
