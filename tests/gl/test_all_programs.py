"""Every shipped shader program of every visual compiles and links.

Each visual module (``render/visuals/<name>/visual.py``) declares in ``PROGRAMS`` the programs it
can build and the defines of every variant it uses; this compiles each variant, and checks that
every shader file of the visual's folder belongs to a declared program.
"""

from __future__ import annotations

import importlib
from importlib import resources

import moderngl
import pytest

from geoshade.render.shaders import STAGES, preprocess

VISUALS_PKG = "geoshade.render.visuals"
SHADER_SUFFIXES = {f".{s}" for s in STAGES} | {".glsl"}


def _visuals() -> dict[str, object]:
    """name -> visual module, for every visual folder that holds shader files."""
    found = {}
    for entry in sorted(resources.files(VISUALS_PKG).iterdir(), key=lambda e: e.name):
        if not entry.is_dir() or not entry.joinpath("visual.py").is_file():
            continue
        if not any(f.name.endswith(tuple(SHADER_SUFFIXES)) for f in entry.iterdir()):
            continue  # a visual that reuses another's shaders
        found[entry.name] = importlib.import_module(f"{VISUALS_PKG}.{entry.name}.visual")
    return found


VISUALS = _visuals()
CASES = [pytest.param(name, spec, i, id=f"{name}-{spec.name}-{i}")
         for name, mod in VISUALS.items() for spec in getattr(mod, "PROGRAMS", ())
         for i in range(len(spec.variants))]


def test_every_visual_with_shaders_declares_its_programs():
    assert set(VISUALS) >= {"voxels", "raycast", "isosurface", "grid", "stacks", "wells"}
    for name, mod in VISUALS.items():
        assert getattr(mod, "PROGRAMS", None), f"{name}/visual.py declares no PROGRAMS"


@pytest.mark.parametrize("name", sorted(VISUALS))
def test_every_shader_file_belongs_to_a_declared_program(name):
    mod = VISUALS[name]
    pkg = mod.PKG
    used: set[str] = set()
    for spec in mod.PROGRAMS:
        for fname in spec.stages.values():
            used.update(preprocess(pkg, fname, strict=False).files)  # includes too
    shipped = {f.name for f in resources.files(pkg).iterdir()
               if f.name.endswith(tuple(SHADER_SUFFIXES))}
    assert not shipped - used, f"{name}: shader files no declared program uses"


@pytest.mark.parametrize(("name", "spec", "variant"), CASES)
def test_program_compiles_and_links(ctx, name, spec, variant):
    prog = spec.load(ctx, VISUALS[name].PKG, spec.variants[variant])
    try:
        assert isinstance(prog, moderngl.Program) and prog.glo > 0
    finally:
        prog.release()
