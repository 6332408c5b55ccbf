"""The package's structure bars (issue 40): no function over 150 lines, and the launch's rooms import one way.

Read from the sources with :mod:`ast`; nothing is run.
"""
from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "cushion_clutch"
MAX_LINES = 150
#: functions over the bar that their owners shorten (issue 40): their length today, which must not grow
KNOWN_LONG = {"cli.py:build_parser": 209, "fe/heat_mesh.py:sector_mesh": 164}
#: the launch's rooms from the ground up: a room imports only rooms below it (and the rest of the package)
LAUNCH_ROOMS = ("scenario", "plant", "tcu", "results", "simulate", "report", "fleet")


def _functions():
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield f"{path.relative_to(PACKAGE).as_posix()}:{node.name}", node.end_lineno - node.lineno + 1


def test_no_function_is_longer_than_the_bar():
    long = {name: n for name, n in _functions() if n > MAX_LINES}
    unknown = {k: v for k, v in long.items() if k not in KNOWN_LONG}
    grown = {k: v for k, v in long.items() if k in KNOWN_LONG and v > KNOWN_LONG[k]}
    assert not unknown and not grown, f"functions over {MAX_LINES} lines: {unknown or grown}"


def test_the_launch_loop_is_short():
    lengths = dict(_functions())
    assert lengths["launch/simulate.py:simulate_launches"] <= 120


def _room(module: str) -> str | None:
    """The launch room of a dotted module name under ``cushion_clutch.launch`` (None: outside the launch)."""
    parts = module.split(".")
    if parts[:2] != ["cushion_clutch", "launch"] or len(parts) < 3:
        return None
    return parts[2] if parts[2] in LAUNCH_ROOMS else None


def _imports(path: Path) -> set[str]:
    """The modules a file imports (relative imports resolved), function-level imports included."""
    module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    package = module.rsplit(".", 1)[0] if path.name != "__init__.py" else module.removesuffix(".__init__")
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            out.add(name)
            out.update(f"{name}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_launch_rooms_import_only_downwards():
    """scenario/ imports no launch code; plant/ only the scenario; tcu/ and results/ below them; ... (the
    ``farm-studio look cushion_clutch/launch`` drawing: 0 arrows back up, 0 circles)."""
    order = {room: i for i, room in enumerate(LAUNCH_ROOMS)}
    order["results"] = order["tcu"]                      # side by side on one floor
    bad = []
    for path in sorted((PACKAGE / "launch").rglob("*.py")):
        rel = path.relative_to(PACKAGE / "launch")
        here = rel.parts[0].removesuffix(".py")
        if here not in order:
            continue
        for name in _imports(path):
            there = _room(name)
            if there is not None and there != here and order[there] >= order[here]:
                bad.append(f"launch/{rel.as_posix()} imports {name}")
    assert not bad, "\n".join(bad)
