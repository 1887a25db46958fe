"""A small, strict GLSL preprocessor and program loader.

Shader files live next to the visual that owns them (``render/visuals/<name>/``) and shared code
in ``render/shaders/include/``; both are read with :mod:`importlib.resources`.

Rules:

- ``#include "file.glsl"`` is resolved in the visual's folder, then in the shared include folder;
  a missing file is an error. A file is included once per stage.
- A shader declares each define it expects with ``#pragma geoshade define NAME``. The loader
  injects ``#define NAME value`` after ``#version``; a define given but not declared, or declared
  but not given, is an error (no silent typos).
- ``#line`` directives keep compile errors pointing at the right file and line; the error text
  is rewritten to show file names instead of source-string numbers.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from importlib import resources

import moderngl

from geoshade.errors import EXIT_SHADER, GeoshadeError

INCLUDE_PKG = "geoshade.render.shaders.include"
_INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
_DECLARE_RE = re.compile(r"^\s*#\s*pragma\s+geoshade\s+define\s+(\w+)\s*$")
_VERSION_RE = re.compile(r"^\s*#\s*version\s+.*$")
STAGES = {
    "vert": "vertex_shader",
    "tesc": "tess_control_shader",
    "tese": "tess_evaluation_shader",
    "geom": "geometry_shader",
    "frag": "fragment_shader",
    "comp": "compute_shader",
}


class ShaderError(GeoshadeError):
    """A shader could not be preprocessed or compiled (a bug in geoshade, or a driver limit)."""

    exit_code = EXIT_SHADER


def _read(package: str, name: str) -> str | None:
    try:
        res = resources.files(package).joinpath(name)
        if res.is_file():
            return res.read_text(encoding="utf-8")
    except (ModuleNotFoundError, FileNotFoundError):
        return None
    return None


@dataclass
class Source:
    """The preprocessed text of one stage and its file table (source-string number -> name)."""

    text: str
    files: list[str] = field(default_factory=list)
    declared: set[str] = field(default_factory=set)

    def explain(self, log: str) -> str:
        """Rewrite ``0:12(3)`` / ``0(12)`` references in a driver log to ``file:12``."""

        def sub(m: re.Match) -> str:
            idx, line = int(m.group(1)), m.group(2)
            name = self.files[idx] if idx < len(self.files) else f"<{idx}>"
            return f"{name}:{line}"

        log = re.sub(r"\b(\d+):(\d+)\(\d+\)", sub, log)
        return re.sub(r"\b(\d+)\((\d+)\)", sub, log)


def preprocess(package: str, name: str, defines: dict | None = None, strict: bool = True
               ) -> Source:
    """Expand includes and inject defines for one shader file of ``package``.

    >>> src = preprocess("geoshade.render.visuals.voxels", "voxel.frag",
    ...                  {"NORMAL_MODE": 0})  # doctest: +SKIP
    """
    defines = dict(defines or {})
    src = Source(text="")
    out: list[str] = []
    seen: set[str] = set()

    def expand(pkg: str, fname: str, stack: tuple[str, ...]) -> None:
        text = _read(pkg, fname)
        if text is None and pkg != INCLUDE_PKG:
            pkg, text = INCLUDE_PKG, _read(INCLUDE_PKG, fname)
        if text is None:
            where = f" (included from {stack[-1]})" if stack else ""
            raise ShaderError(f"shader file {fname!r} not found in {package} or shared include"
                              f"{where}")
        key = f"{pkg}/{fname}"
        if key in seen:
            return
        seen.add(key)
        fid = len(src.files)
        src.files.append(fname)
        if stack:
            out.append(f"#line 1 {fid}")
        for lineno, line in enumerate(text.splitlines(), start=1):
            if _VERSION_RE.match(line):
                if stack:
                    raise ShaderError(
                        f"{fname}:{lineno}: #version is only allowed in the main file")
                out.append(line)
                for k, v in defines.items():
                    out.append(f"#define {k} {_glsl_value(v)}")
                out.append(f"#line {lineno + 1} {fid}")
                continue
            m = _DECLARE_RE.match(line)
            if m:
                src.declared.add(m.group(1))
                out.append("")
                continue
            m = _INCLUDE_RE.match(line)
            if m:
                expand(pkg, m.group(1), (*stack, fname))
                out.append(f"#line {lineno + 1} {fid}")
                continue
            out.append(line)

    expand(package, name, ())
    if not out or not _VERSION_RE.match(out[0]):
        raise ShaderError(f"{name}: the first line must be #version")
    src.text = "\n".join(out) + "\n"
    if not strict:
        return src
    unknown = set(defines) - src.declared
    missing = src.declared - set(defines)
    if unknown:
        raise ShaderError(f"{name}: unknown define(s) {sorted(unknown)}; declared: "
                          f"{sorted(src.declared)}")
    if missing:
        raise ShaderError(f"{name}: define(s) {sorted(missing)} declared but not given")
    return src


@dataclass(frozen=True)
class ProgramSpec:
    """A program a visual can build: its stage files and the defines of each variant it uses.

    Each visual module lists its programs in ``PROGRAMS``, so that one test compiles every
    shipped program of every visual (``tests/gl/test_all_programs.py``).
    """

    name: str
    stages: dict[str, str]
    variants: tuple[dict, ...] = ({},)
    varyings: tuple[str, ...] = ()

    def load(self, ctx: moderngl.Context, package: str, defines: dict | None = None
             ) -> moderngl.Program:
        """:func:`load_program` of these stages with ``defines`` (one variant's)."""
        return load_program(ctx, package, self.stages, defines, varyings=self.varyings)


def _glsl_value(v) -> str:
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def load_program(ctx: moderngl.Context, package: str, stages: dict[str, str],
                 defines: dict | None = None, varyings=(), per_stage_defines: dict | None = None
                 ) -> moderngl.Program:
    """Compile a program from shader files of ``package``.

    Parameters
    ----------
    stages : dict
        Stage key (``vert tesc tese geom frag comp``) -> file name.
    defines : dict
        Injected into every stage; each stage must declare exactly the names it uses, so the
        loader only passes a stage the defines it declares (use ``per_stage_defines`` to give one
        stage more).
    """
    defines = dict(defines or {})
    sources: dict[str, Source] = {}
    for stage, fname in stages.items():
        if stage not in STAGES:
            raise ShaderError(f"unknown shader stage {stage!r}; expected one of {list(STAGES)}")
        wanted = preprocess(package, fname, None, strict=False).declared
        given = {k: v for k, v in defines.items() if k in wanted}
        given.update((per_stage_defines or {}).get(stage, {}))
        sources[stage] = preprocess(package, fname, given)
    used = set().union(*(s.declared for s in sources.values())) if sources else set()
    unused = set(defines) - used
    if unused:
        raise ShaderError(f"{package}: define(s) {sorted(unused)} not declared by any stage")
    kwargs = {STAGES[k]: s.text for k, s in sources.items()}
    try:
        if "comp" in sources:
            return ctx.compute_shader(sources["comp"].text)
        return ctx.program(**kwargs, varyings=tuple(varyings))
    except Exception as exc:
        log = str(exc)
        for stage, s in sources.items():
            if STAGES[stage] in log or len(sources) == 1:
                log = s.explain(log)
                break
        raise ShaderError(f"{package}: shader compile/link failed:\n{log}") from None
