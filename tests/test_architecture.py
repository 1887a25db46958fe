"""No import cycle among geoshade's modules (function-level imports count too).

The import-linter contracts in ``pyproject.toml`` (``lint-imports``) check the layers between
packages; this test checks every module against every other, with grimp.
"""

from __future__ import annotations

import itertools

import grimp  # comes with import-linter (the test extra)


def _strongly_connected(graph, modules) -> list[set[str]]:
    """Tarjan's algorithm (iterative): the components of more than one module."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[set[str]] = []
    counter = 0
    for root in sorted(modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.find_modules_directly_imported_by(w)))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = set()
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.add(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(comp)
    return out


def _shortest_cycle(graph, component: set[str]) -> list[str]:
    """The shortest cycle through the modules of one component, as a closed path."""
    best: list[str] | None = None
    for a in sorted(component):
        for b in sorted(graph.find_modules_directly_imported_by(a) & component):
            back = graph.find_shortest_chain(importer=b, imported=a)
            if back is not None and (best is None or len(back) + 1 < len(best)):
                best = [a, *back]
    assert best is not None
    return best


def _where(graph, a: str, b: str) -> str:
    details = graph.get_import_details(importer=a, imported=b)
    return f"line {details[0]['line_number']}" if details else "?"


def find_cycles() -> list[str]:
    """One line per cycle: the shortest cycle of each strongly connected set of modules."""
    graph = grimp.build_graph("geoshade", include_external_packages=False)
    lines = []
    for comp in _strongly_connected(graph, graph.modules):
        cyc = _shortest_cycle(graph, comp)
        steps = [f"{a} ({_where(graph, a, b)})" for a, b in itertools.pairwise(cyc)]
        lines.append(" -> ".join([*steps, cyc[-1]])
                     + (f"  [{len(comp)} modules in this tangle]" if len(comp) > 2 else ""))
    return sorted(lines)


def test_cycle_finder_sees_a_cycle(tmp_path, monkeypatch):
    pkg = tmp_path / "cyclepkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from cyclepkg import b  # noqa\n")
    (pkg / "b.py").write_text("from cyclepkg import c\n")
    (pkg / "c.py").write_text("import cyclepkg.a\n")
    (pkg / "d.py").write_text("import cyclepkg.a\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    graph = grimp.build_graph("cyclepkg", include_external_packages=False, cache_dir=None)
    comps = _strongly_connected(graph, graph.modules)
    assert comps == [{"cyclepkg.a", "cyclepkg.b", "cyclepkg.c"}]
    assert _shortest_cycle(graph, comps[0]) == ["cyclepkg.a", "cyclepkg.b", "cyclepkg.c",
                                                "cyclepkg.a"]


def test_no_import_cycles():
    cycles = find_cycles()
    assert not cycles, ("import cycles among geoshade modules (shortest cycle of each; a -> b "
                        "means a imports b at that line):\n  " + "\n  ".join(cycles))
