"""The package's imports go one way: no import cycles among drill_sim_ros modules, and the
rooms below (model/, control/) never import the rooms above them.

The graph is read from the source with ``ast``: every ``import`` in a module counts, also one
inside a function (a lazy import hides a cycle, it does not open it) or under
``TYPE_CHECKING``. Dynamic imports (a user's controller, message classes) are not edges.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = "drill_sim_ros"
ROOT = Path(__file__).resolve().parents[1]
# room -> the rooms it must not import (model/ is the core: it imports only itself)
FORBIDDEN = {"control": ("ros", "viz", "archive", "study")}
CORE = "model"


def module_files(root: Path = ROOT) -> dict[str, Path]:
    """Dotted module name -> its file, for every module of the package under ``root``."""
    out = {}
    for path in sorted((root / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _imported(node: ast.Import | ast.ImportFrom, module: str, is_package: bool) -> list[str]:
    """The dotted names an import statement in ``module`` may refer to, most specific first."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    base = node.module or ""
    if node.level:                                   # relative: from the module's package
        anchor = module.split(".") if is_package else module.split(".")[:-1]
        anchor = anchor[:len(anchor) - node.level + 1]
        base = ".".join([*anchor, base] if base else anchor)
    return [f"{base}.{alias.name}" for alias in node.names] + [base]


def _resolve(name: str, modules: dict[str, Path]) -> str | None:
    """The package module ``name`` is in (``a.b.func`` -> ``a.b``), or None outside it."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def import_graph(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the package modules it imports (an attribute of a module is that module)."""
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            names = _imported(node, name, path.name == "__init__.py")
            if isinstance(node, ast.ImportFrom):      # from pkg import sub: the submodule
                names = [n for n in names[:-1] if n in modules] or names[-1:]
            for target in filter(None, (_resolve(n, modules) for n in names)):
                if target != name:
                    graph[name].add(target)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str]:
    """One import cycle as ``[a, b, ..., a]``, or [] if there is none (depth-first)."""
    state: dict[str, int] = {}                        # 1: on the path, 2: done
    for start in sorted(graph):
        if start in state:
            continue
        path, todo = [start], [iter(sorted(graph[start]))]
        state[start] = 1
        while todo:
            nxt = next(todo[-1], None)
            if nxt is None:
                state[path.pop()] = 2
                todo.pop()
            elif state.get(nxt) == 1:
                return [*path[path.index(nxt):], nxt]
            elif nxt not in state:
                state[nxt] = 1
                path.append(nxt)
                todo.append(iter(sorted(graph[nxt])))
    return []


def _room(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 2 else ""         # drill_sim_ros.<room>.<module>


def arrows_up(graph: dict[str, set[str]]) -> list[str]:
    """``a -> b`` for each import of a room above by model/ or control/."""
    out = []
    for module, targets in sorted(graph.items()):
        room = _room(module)
        for target in sorted(targets):
            above_core = room == CORE and _room(target) != CORE
            if above_core or _room(target) in FORBIDDEN.get(room, ()):
                out.append(f"{module} -> {target}")
    return out


def test_the_graph_is_read_from_the_source() -> None:
    graph = import_graph(module_files())
    assert "drill_sim_ros.closed_loop_cli" in graph["drill_sim_ros.cli"]
    assert "drill_sim_ros.ros.closed_loop" in graph["drill_sim_ros.closed_loop_cli"]  # lazy
    assert "drill_sim_ros.model.validate_input" in graph["drill_sim_ros.model.presets"]
    assert "drill_sim_ros.model.kernel" in graph["drill_sim_ros.model.simulator"]


def test_the_checks_see_a_cycle_and_an_arrow_up() -> None:
    graph = {"drill_sim_ros.model.a": {"drill_sim_ros.model.b"},
             "drill_sim_ros.model.b": {"drill_sim_ros.model.c"},
             "drill_sim_ros.model.c": {"drill_sim_ros.model.a", "drill_sim_ros.ros.x"},
             "drill_sim_ros.control.d": {"drill_sim_ros.viz.y", "drill_sim_ros.model.a"},
             "drill_sim_ros.ros.x": set(), "drill_sim_ros.viz.y": set()}
    assert find_cycle(graph) == ["drill_sim_ros.model.a", "drill_sim_ros.model.b",
                                 "drill_sim_ros.model.c", "drill_sim_ros.model.a"]
    assert arrows_up(graph) == ["drill_sim_ros.control.d -> drill_sim_ros.viz.y",
                                "drill_sim_ros.model.c -> drill_sim_ros.ros.x"]
    del graph["drill_sim_ros.model.c"]
    graph["drill_sim_ros.model.b"] = set()
    assert find_cycle(graph) == []


def test_no_import_cycles() -> None:
    assert find_cycle(import_graph(module_files())) == []


def test_model_and_control_import_nothing_above_them() -> None:
    assert arrows_up(import_graph(module_files())) == []
