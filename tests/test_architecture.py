"""The package's layers: no import crosses a layer the wrong way (docs/architecture.md).

Every module of ``feederkit`` belongs to a layer, named by its first dotted component
(``feederkit.planning.api`` is ``planning``) or, where a package holds two layers, by a
longer prefix (``machine.build`` builds the abstract machine from geometry, the rest of
``machine`` never looks at geometry). ``ALLOWED`` lists, once, which layers each layer may
import; third-party libraries with a single home are in ``LIBRARIES``. The check reads the
source with ``ast``, so it sees imports inside functions too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "feederkit"

_BASE = {"errors", "angles", "jsonio", "words"}
_GEOMETRY = _BASE | {"hull", "outline", "part"}
_MODEL = _GEOMETRY | {"sensors", "uncertainty", "mechanics", "machine", "machine.build"}
_FILES = _MODEL | {"importers", "landing", "catalog", "sources", "loading", "cell"}

ALLOWED: dict[str, set[str]] = {
    "feederkit": set(),  # the package's __init__
    "__main__": {"cli"},  # ``python -m feederkit``: the command line's entry
    "errors": set(),
    "words": set(),
    "angles": set(),
    "jsonio": {"errors"},
    "sensors": {"errors"},
    "hull": set(),
    "outline": {"errors", "jsonio"},
    "part": {"errors", "hull", "outline"},
    "uncertainty": _GEOMETRY,
    # Section 3: exact from the hull; knows sensors (polygon classes, analysis), not machines.
    "mechanics": _GEOMETRY | {"sensors", "uncertainty"},
    # The abstract machine: no geometry, so machines can be built by hand. It records the
    # declared uncertainty (a value of three bounds) it was built under.
    "machine": {"errors", "angles", "sensors", "uncertainty"},
    "machine.build": {"errors", "angles", "sensors", "uncertainty", "machine", "mechanics"},
    # The planners know only the abstract machine (which re-exports the sensor's Grouping).
    "planning": {"errors", "angles", "words", "uncertainty", "machine"},
    "importers": _GEOMETRY | {"mechanics"},
    # Landings (docs/landings.md): the ways a part lands, from its outline or its mesh poses.
    "landing": _GEOMETRY | {"mechanics", "importers"},
    # Planning over landings: each landing is one member of a mix (section 8).
    "landing.plan": _FILES | {"planning", "plans", "mix"},
    "catalog": _GEOMETRY | {"importers", "landing"},
    "sources": _GEOMETRY | {"importers", "catalog"},
    "loading": _GEOMETRY | {"sensors", "mechanics", "importers", "catalog", "sources"},
    # The cell profile (design.md): the feeder's sensor, robot and belt, read once; it turns
    # them into the planners' abstract action costs and the cycle time of a plan.
    "cell": _MODEL | {"planning"},
    "plans": _FILES | {"planning"},
    "mix": _FILES | {"planning", "plans"},
    "reports": _FILES | {"planning", "plans"},
    "sim": _FILES | {"planning", "plans"},
    # Sensor design: the tolerances at which parts and plans change (uses mixes and plans).
    "design": _FILES | {"planning", "plans", "mix", "reports"},
    "demo": _FILES | {"planning", "plans", "mix", "landing.plan", "design", "reports", "sim"},
    "cli": _FILES
    | {"feederkit", "planning", "plans", "mix", "landing.plan", "design", "reports", "sim", "demo"},
}

LIBRARIES: dict[str, set[str]] = {
    "rich": {"cli"},
    "typer": {"cli"},
    "matplotlib": {"reports", "design"},  # the modules that draw
    "mujoco": {"sim"},
    "ezdxf": {"importers"},
    "trimesh": {"importers"},
}

KNOWN_EXCEPTIONS: set[tuple[str, str]] = {
    # Transitional re-export: ``from feederkit.machine import build_machine`` still works
    # while callers move to ``feederkit.machine.build``.
    ("feederkit.machine", "feederkit.machine.build"),
}


def layer_of(module: str) -> str:
    """The layer of a dotted module name (``feederkit.x.y`` -> ``x``, or a longer key)."""
    parts = module.split(".")
    if len(parts) == 1:
        return "feederkit"
    for k in range(len(parts) - 1, 1, -1):
        key = ".".join(parts[1 : k + 1])
        if key in ALLOWED:
            return key
    return parts[1]


def modules() -> list[tuple[str, Path]]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts)
        out.append((name.removesuffix(".__init__"), path))
    return out


def imports(module: str, path: Path) -> list[str]:
    """Absolute names of everything ``module`` imports (relative imports resolved)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.extend(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                out.append(".".join(base + ([node.module] if node.module else [])))
            elif node.module:
                out.append(node.module)
    return out


def violations() -> list[str]:
    bad = []
    for module, path in modules():
        here = layer_of(module)
        if here not in ALLOWED:
            bad.append(f"{module}: layer {here!r} is not in ALLOWED (docs/architecture.md)")
            continue
        for target in imports(module, path):
            top = target.split(".")[0]
            if top == "feederkit":
                there = layer_of(target)
                if there == here or (module, target) in KNOWN_EXCEPTIONS:
                    continue
                if there not in ALLOWED[here]:
                    bad.append(f"{module} imports {target}: {here} may not import {there}")
            elif top in LIBRARIES and here not in LIBRARIES[top]:
                bad.append(f"{module} imports {target}: only {sorted(LIBRARIES[top])} may")
    return bad


def test_no_import_crosses_a_layer_the_wrong_way() -> None:
    assert violations() == []


def test_every_allowed_layer_exists() -> None:
    present = {layer_of(m) for m, _ in modules()}
    assert set(ALLOWED) - present <= {"loading", "outputs", "demo", "design", "uncertainty", "cell"}


def test_known_exceptions_are_still_needed() -> None:
    """An exception that no module needs any more must go."""
    used = {(m, t) for m, p in modules() for t in imports(m, p)}
    assert used >= KNOWN_EXCEPTIONS


@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("from feederkit.sensors import NoSensor\n", "planning may not import sensors"),
        ("from feederkit.mechanics.push import push\n", "planning may not import mechanics"),
        ("import rich\n", "only ['cli'] may"),
    ],
)
def test_the_check_catches_a_wrong_arrow(tmp_path, monkeypatch, source, message) -> None:
    """The check itself works: a planner importing sensors, mechanics or rich is caught."""
    pkg = tmp_path / "feederkit" / "planning"
    pkg.mkdir(parents=True)
    (tmp_path / "feederkit" / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "bad.py").write_text(source)
    monkeypatch.setattr(__import__(__name__), "PACKAGE", tmp_path / "feederkit")
    assert any(message in v for v in violations())
