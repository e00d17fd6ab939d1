"""The package's stages import only from stages below them (docs/architecture.md)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "upperpose"

# Lower number = lower stage. A module may import from its own stage or any lower one.
STAGES = {
    "upperpose._upperpose": 0,
    "upperpose.exceptions": 0,
    "upperpose.model": 0,
    "upperpose.draw": 0,
    "upperpose.result": 0,
    "upperpose.io": 1,
    "upperpose.features": 2,
    "upperpose.fit": 3,
    "upperpose": 4,  # the package root: the public API, above the product's stages
    "upperpose.batch": 4,  # many videos at once, through the API's stages
    "upperpose.lab": 5,
    "upperpose.commands": 6,
    "upperpose.cli": 6,
    "upperpose.__main__": 7,  # python -m upperpose
}


def stage(module: str) -> int:
    """The stage of a dotted module name: its longest prefix in STAGES."""
    parts = module.split(".")
    for n in range(len(parts), 0, -1):
        name = ".".join(parts[:n])
        if name in STAGES:
            return STAGES[name]
    raise KeyError(module)


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imported(tree: ast.AST) -> list[str]:
    """Every upperpose module an AST imports, wherever the import statement stands."""
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
    return [n for n in names if n == "upperpose" or n.startswith("upperpose.")]


MODULES = sorted(PACKAGE.rglob("*.py"))


def test_every_module_has_a_stage() -> None:
    assert len(MODULES) > 50
    for path in MODULES:
        stage(module_name(path))


@pytest.mark.parametrize("path", MODULES, ids=lambda p: module_name(p))
def test_no_upward_import(path: Path) -> None:
    me = module_name(path)
    upward = [m for m in imported(ast.parse(path.read_text())) if stage(m) > stage(me)]
    assert not upward, f"{me} (stage {stage(me)}) imports from a higher stage: {upward}"


def test_the_check_catches_an_upward_import() -> None:
    tree = ast.parse("def f():\n    from upperpose.lab.evaluate import evaluate\n")
    assert [m for m in imported(tree) if stage(m) > stage("upperpose.fit.tracker")] == ["upperpose.lab.evaluate"]
    assert stage("upperpose.io.video") < stage("upperpose.features.extractor") < stage("upperpose.fit.root")
