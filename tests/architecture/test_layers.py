"""The import rules of docs/design.md ("Layers"), checked on the source by an AST walk: any
back edge fails the suite, naming the module, the line and the import."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "vo_doppler"
BASE = {
    "bounds",
    "child_process",
    "errors",
    "choices",
    "geo",
    "memory",
    "model",
    "robust",
    "time_hints",
    "units",
}
STAGES = {"vo", "gnss", "heading", "fusion", "lowcost", "eval"}
ALLOWED: dict[str, set[str]] = {
    "errors": set(),
    "child_process": set(),
    "choices": {"errors"},
    "geo": {"errors"},
    "memory": set(),
    "robust": set(),
    "units": set(),
    "bounds": {"geo"},
    "time_hints": {"errors", "model"},
    "model": {"errors", "geo", "model"},
    "vo": BASE | {"vo"},
    "gnss": BASE | {"gnss"},
    "lowcost": BASE | {"lowcost"},
    "eval": BASE | {"eval"},
    "heading": BASE | {"heading", "gnss", "checks"},
    "fusion": BASE | {"fusion", "heading", "gnss", "lowcost"},
    "io": BASE | {"io"},
    "checks": BASE,
    "sim": BASE | STAGES | {"io", "sim"},
    "run_stages": BASE | STAGES | {"io"},
    "run": BASE | STAGES | {"checks", "io", "run_stages"},
    "report": BASE | STAGES | {"checks", "io", "run", "run_stages", "report"},
    "job": BASE | STAGES | {"io", "run", "run_stages", "report"},
    "batch": BASE | STAGES | {"io", "run", "run_stages", "report", "job"},
}
"""Layer → the layers it may import. Commands and the CLI may import anything."""


def layer_of(module: str) -> str:
    """'vo_doppler.heading.pipeline' → 'heading'; top-level modules are their own layer."""
    return module.split(".")[1] if "." in module else module


def project_imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every ``vo_doppler`` import in a file, function-level ones included."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
        found += [(node.lineno, name) for name in names if name.startswith("vo_doppler.")]
    return found


def violations(package: Path = PACKAGE) -> list[str]:
    out = []
    for path in sorted(package.rglob("*.py")):
        relative = path.relative_to(package.parent).with_suffix("")
        module = ".".join(relative.parts).removesuffix(".__init__")
        layer = layer_of(module)
        if layer not in ALLOWED:
            continue
        for line, imported in project_imports(path):
            target = layer_of(imported)
            if target not in ALLOWED[layer]:
                out.append(f"{path.relative_to(package.parent)}:{line}: {layer} imports {imported}")
    return out


def test_no_module_imports_against_the_layers():
    assert violations() == []


def test_every_package_has_a_rule():
    packages = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    modules = {p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    assert (packages | modules) - set(ALLOWED) <= {"commands", "cli", "__main__"}


def test_a_back_edge_is_caught(tmp_path):
    fake = tmp_path / "vo_doppler"
    (fake / "heading").mkdir(parents=True)
    (fake / "heading" / "bad.py").write_text("def f():\n    from vo_doppler.io.can import x\n")
    (fake / "model").mkdir()
    (fake / "model" / "ok.py").write_text("from vo_doppler.geo import EnuFrame\n")
    assert violations(fake) == ["vo_doppler/heading/bad.py:2: heading imports vo_doppler.io.can"]


@pytest.mark.parametrize(
    ("module", "layer"), [("vo_doppler.run", "run"), ("vo_doppler.io.can", "io"), ("cli", "cli")]
)
def test_layer_of(module, layer):
    assert layer_of(module) == layer


PLACEMENT = {
    "AntennaTrack",
    "antenna_track",
    "_height_sigma",
    "PLACEMENT_VERTICAL_SIGMA_M",
    "ORIGIN_HEIGHT",
    "level_with_yaw",
    "_placing_rows",
    "_carried",
    "weighted_median",
    "PLACEMENT_SPAN_S",
    "PLACEMENT_MIN_FIXES",
    "yaw_offset",
    "initial_yaw_offset",
    "dead_reckoning",
    "correct_all",
}
"""The trajectory placement maths (issue 32): the fusion layer's, not the main job's."""
RUN_MAX_LINES = 250


def defined_names(path: Path) -> set[str]:
    """The names a module defines at its top level (functions, classes, assignments)."""
    names = set()
    for node in ast.parse(path.read_text(), str(path)).body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names |= {target.id for target in targets if isinstance(target, ast.Name)}
    return names


def test_the_placement_maths_live_in_fusion_and_run_py_stays_an_orchestrator():
    fusion = set().union(*(defined_names(p) for p in (PACKAGE / "fusion").glob("*.py")))
    assert fusion >= PLACEMENT
    orchestrators = ("run.py", "run_stages.py", "job.py", "batch.py")
    for name in orchestrators:
        assert defined_names(PACKAGE / name) & PLACEMENT == set(), name
    assert len((PACKAGE / "run.py").read_text().splitlines()) <= RUN_MAX_LINES
