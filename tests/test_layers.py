"""The package layout is the architecture: no package imports one above it, no import loops."""

from __future__ import annotations

import ast
from pathlib import Path

import teachfit

ROOT = Path(teachfit.__file__).parent

#: bottom to top; a package may import only packages of a lower (or its own) layer
LAYERS: tuple[tuple[str, ...], ...] = (
    ("core",),
    ("metrics",),  # statistics of outcomes: needs only core, so every layer may use it
    ("tasks", "control"),
    ("robot",),
    ("demonstrations",),
    ("models",),
    ("trajectories", "skills", "plans"),
    ("capture",),
    ("execution",),
    ("learning",),
    ("viz",),
    ("bench",),
    ("quickstart",),
    ("cli",),
)
RANK = {name: i for i, layer in enumerate(LAYERS) for name in layer}


def _imports() -> dict[tuple[str, str], list[str]]:
    """``(importer, imported) -> [files]`` over every teachfit module (absolute imports)."""
    edges: dict[tuple[str, str], list[str]] = {}
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT)
        if rel.name == "__init__.py" and len(rel.parts) == 1:
            continue  # the top-level package re-exports the public API
        pkg = rel.parts[0] if len(rel.parts) > 1 else rel.stem
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            for name in names:
                parts = name.split(".")
                if parts[0] == "teachfit" and len(parts) > 1 and parts[1] != pkg:
                    edges.setdefault((pkg, parts[1]), []).append(str(rel))
    return edges


def test_every_package_has_a_layer() -> None:
    pkgs = {p.name for p in ROOT.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    pkgs |= {p.stem for p in ROOT.glob("*.py") if p.stem != "__init__"}
    assert pkgs - set(RANK) == set(), "add new packages to LAYERS"


def test_no_package_imports_one_above_it() -> None:
    upward = {
        f"{a} -> {b} ({', '.join(sorted(set(files)))})"
        for (a, b), files in _imports().items()
        if RANK[b] > RANK[a]
    }
    assert not upward


def test_no_two_packages_import_each_other() -> None:
    edges = _imports()
    loops = sorted(f"{a} <-> {b}" for (a, b) in edges if (b, a) in edges and a < b)
    assert not loops


def test_only_robot_and_scene_building_call_mujoco_math() -> None:
    """``mju_*`` quaternion/vector math lives in robot/ and the geometry kernel; scene
    builders (tasks, capture rendering) may use MuJoCo but not its math routines."""
    allowed = {"robot", "core"}
    found = []
    for path in ROOT.rglob("*.py"):
        rel = path.relative_to(ROOT)
        if rel.parts[0] in allowed:
            continue
        if "mju_" in path.read_text():
            found.append(str(rel))
    assert not found


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def _runtime_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement that can run: at module level or inside a function (imported on
    use), but not under ``if TYPE_CHECKING:``, which never runs."""
    found: list[ast.Import | ast.ImportFrom] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            todo.extend(node.orelse)
            continue
        if isinstance(node, ast.Import | ast.ImportFrom):
            found.append(node)
        todo.extend(ast.iter_child_nodes(node))
    return found


def _runtime_edges() -> dict[str, set[str]]:
    """``module -> {teachfit modules it imports when it runs}``, with the package ``__init__``
    each such import runs (but not the module's own packages, already running)."""
    modules = {_module_name(p): p for p in ROOT.rglob("*.py")}
    edges: dict[str, set[str]] = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found: set[str] = set()
        for imp in _runtime_imports(ast.parse(path.read_text())):
            if isinstance(imp, ast.Import):
                found |= {a.name for a in imp.names}
                continue
            base = imp.module or ""
            if imp.level:
                up = package.split(".")[: len(package.split(".")) - imp.level + 1]
                base = ".".join(up + ([base] if base else []))
            found |= {f"{base}.{a.name}" for a in imp.names} | {base}
        ancestors = {".".join(name.split(".")[:i]) for i in range(1, name.count(".") + 1)}
        edges[name] = {m for m in found if m in modules and m != name and m not in ancestors}
    return edges


def test_no_runtime_import_cycle_between_files() -> None:
    """No chain of imports that run (at import time or on use) leads from a file back to
    itself: two files that need each other are one concept, or a third file is missing."""
    edges = _runtime_edges()
    cycles: set[tuple[str, ...]] = set()

    def visit(node: str, stack: list[str], on_stack: set[str], done: set[str]) -> None:
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(edges[node]):
            if nxt in on_stack:
                loop = stack[stack.index(nxt) :]
                k = loop.index(min(loop))
                cycles.add(tuple(loop[k:] + loop[:k]))
            elif nxt not in done:
                visit(nxt, stack, on_stack, done)
        stack.pop()
        on_stack.discard(node)
        done.add(node)

    done: set[str] = set()
    for start in sorted(edges):
        if start not in done:
            visit(start, [], set(), done)
    assert not sorted(" -> ".join(c) for c in cycles)
