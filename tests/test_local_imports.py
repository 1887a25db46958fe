"""Imports are at the top of a module by default (issue 23: dependencies visible). A function may
import locally only where the import is listed, with its reason, in ``pyproject.toml``
``[tool.geoshade.local-imports]`` — GL (moderngl), optional extras and heavy packages kept out of
a module's import, a package ``__init__`` that imports the module, an optional dependency checked
where it is used. Every listed import must still exist (no stale reasons)."""

from __future__ import annotations

import ast
import pathlib
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "geoshade"


def local_imports(tree: ast.AST) -> list[str]:
    """The function-level import statements of a module, as ``ast.unparse`` writes them."""
    out: list[str] = []

    def visit(node: ast.AST, in_func: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                visit(child, True)
            elif isinstance(child, ast.Import | ast.ImportFrom):
                if in_func:
                    out.append(ast.unparse(child))
            else:
                visit(child, in_func)

    visit(tree, False)
    return out


def table() -> dict[str, dict[str, str]]:
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["tool"]["geoshade"]["local-imports"]


def test_every_function_level_import_has_a_listed_reason():
    listed = table()
    unlisted = []
    for path in sorted(SRC.rglob("*.py")):
        rel = str(path.relative_to(ROOT))
        allowed = listed.get(rel, {})
        for stmt in local_imports(ast.parse(path.read_text())):
            if stmt not in allowed:
                unlisted.append(f"{rel}: {stmt}")
    assert not unlisted, ("imports inside functions without a reason in pyproject.toml "
                          "[tool.geoshade.local-imports] (move them to the top, or list them "
                          "with why):\n" + "\n".join(unlisted))


def test_no_stale_or_empty_reasons():
    stale = []
    for rel, entries in table().items():
        path = ROOT / rel
        present = set(local_imports(ast.parse(path.read_text()))) if path.exists() else set()
        for stmt, reason in entries.items():
            if stmt not in present:
                stale.append(f"{rel}: {stmt}")
            assert reason.strip(), f"{rel}: {stmt}: empty reason"
    assert not stale, "listed local imports that are gone:\n" + "\n".join(stale)


def test_no_module_reimports_what_it_imports_at_the_top():
    dup = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text())
        top = {ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)}
        dup += [f"{path.relative_to(ROOT)}: {s}" for s in local_imports(tree) if s in top]
    assert not dup, "\n".join(dup)
