"""Imports are at the top of a module (issue 23: dependencies visible; issue 30: one rule).

A function may import late only a package the one rule in ``pyproject.toml``
``[tool.geoshade.local-imports] late`` names: GL, Qt, Jupyter, the web server, dask clusters,
and the packages measured heavy or optional (the readers), or a geoshade module whose import
loads one of them through the imports at its top (``geoshade.render.context`` is GL,
``geoshade.io.grids.restart_wells`` loads resfo). ``import geoshade.io`` imports no reader (the
format table names them), so nothing else needs to wait. The two short per-file lists beside
the rule are ``cycles`` (a package's ``__init__`` imports the module: a top-level import would
be a loop) and ``to-move`` (imports in files other engineers are editing, to be moved when they
are done); each entry must still be needed.
"""

from __future__ import annotations

import ast
import functools
import pathlib
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "geoshade"


def local_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """The function-level import statements of a module."""
    out: list[ast.Import | ast.ImportFrom] = []

    def visit(node: ast.AST, in_func: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                visit(child, True)
            elif isinstance(child, ast.Import | ast.ImportFrom):
                if in_func:
                    out.append(child)
            else:
                visit(child, in_func)

    visit(tree, False)
    return out


def _module_of(path: pathlib.Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(stmt: ast.Import | ast.ImportFrom, path: pathlib.Path) -> list[str]:
    """The absolute names of what ``stmt`` imports (``from geoshade import core`` imports the
    module ``geoshade.core``; ``from numba import njit`` the package ``numba``)."""
    if isinstance(stmt, ast.Import):
        return [a.name for a in stmt.names]
    base = stmt.module or ""
    if stmt.level:
        pkg = _module_of(path).split(".")
        if path.name != "__init__.py":
            pkg = pkg[:-1]
        pkg = pkg[: len(pkg) - (stmt.level - 1)]
        base = ".".join([*pkg, *([base] if base else [])])
    out = []
    for a in stmt.names:
        sub = f"{base}.{a.name}"
        rel = pathlib.Path(*sub.split("."))
        is_module = (SRC.parent / rel).with_suffix(".py").exists() or (SRC.parent / rel).is_dir()
        out.append(sub if base.startswith("geoshade") and is_module else base)
    return out


def rule() -> dict:
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["tool"]["geoshade"]["local-imports"]


def _under(module: str, names) -> bool:
    return any(module == n or module.startswith(n + ".") for n in names)


def _file_of(module: str) -> pathlib.Path | None:
    base = SRC.parent / pathlib.Path(*module.split("."))
    for f in (base.with_suffix(".py"), base / "__init__.py"):
        if f.is_file():
            return f
    return None


@functools.cache
def _top_imports(module: str) -> list[str]:
    """What geoshade ``module`` imports at its top (its parent packages' ``__init__`` too)."""
    out = [".".join(module.split(".")[:k]) for k in range(2, module.count(".") + 1)]
    f = _file_of(module)
    if f is not None:
        tree = ast.parse(f.read_text())
        out += [m for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)
                for m in imported_modules(n, f)]
    return out


def wraps_late(module: str, late, _seen: dict | None = None) -> bool:
    """Whether importing geoshade ``module`` imports a ``late`` package, through the imports at
    the top of it and of the geoshade modules those load (importing it late is importing that
    package late: ``geoshade.io.grids.restart_wells`` loads resfo)."""
    seen = {} if _seen is None else _seen
    if module in seen:
        return seen[module]
    seen[module] = False   # a cycle adds nothing
    found = False
    for m in _top_imports(module) if module.startswith("geoshade") else ():
        if _under(m, late) or (m.startswith("geoshade") and wraps_late(m, late, seen)):
            found = True
            break
    seen[module] = found
    return found


def refused() -> list[tuple[str, str, str]]:
    """``(file, statement, module)`` of every function-level import the rule refuses, before
    the per-file lists."""
    late = rule()["late"]
    seen: dict = {}
    out = []
    for path in sorted(SRC.rglob("*.py")):
        rel = str(path.relative_to(ROOT))
        for stmt in local_imports(ast.parse(path.read_text())):
            for mod in dict.fromkeys(imported_modules(stmt, path)):
                if not (_under(mod, late) or wraps_late(mod, late, seen)):
                    out.append((rel, ast.unparse(stmt), mod))
    return out


def test_imports_the_rule_refuses_are_only_the_listed_exceptions():
    r = rule()
    listed = {**{f: list(v) for f, v in r.get("cycles", {}).items()}}
    for f, v in r.get("to-move", {}).items():
        listed.setdefault(f, []).extend(v)
    bad = [f"{f}: {s}" for f, s, m in refused() if m not in listed.get(f, ())]
    assert not bad, ("imports inside functions the rule of pyproject.toml [tool.geoshade."
                     "local-imports] refuses (move them to the top of the module; only GL, Qt, "
                     "Jupyter, aiohttp, dask and the heavy or optional packages of `late` may "
                     "wait):\n" + "\n".join(bad))


def test_no_stale_exception():
    r = rule()
    seen = {(f, m) for f, _, m in refused()}
    stale = []
    for key in ("cycles", "to-move"):
        for f, mods in r.get(key, {}).items():
            stale += [f"{key}: {f}: {m}" for m in mods if (f, m) not in seen]
    assert not stale, "listed exceptions no longer needed:\n" + "\n".join(stale)


def test_the_rule_is_short():
    r = rule()
    assert len(r["late"]) <= 40
    assert sum(len(v) for v in r.get("cycles", {}).values()) <= 10


def test_resolves_relative_and_package_imports():
    path = SRC / "cli" / "demo.py"
    tree = ast.parse("def f():\n    from geoshade import core\n    from ..io import formats\n"
                     "    from numba import njit\n    import dask.array as da\n")
    mods = [m for s in local_imports(tree) for m in imported_modules(s, path)]
    assert mods == ["geoshade.core", "geoshade.io.formats", "numba", "dask.array"]


def test_no_module_reimports_what_it_imports_at_the_top():
    dup = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text())
        top = {ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)}
        dup += [f"{path.relative_to(ROOT)}: {ast.unparse(s)}" for s in local_imports(tree)
                if ast.unparse(s) in top]
    assert not dup, "\n".join(dup)
