"""The discrepancy package's shape (issue 30): no two of its modules import each other, it names no `level_g` (the
base rig's level column: a run's level comes from `jointcal.io.level_column`) and calls no `harmonic_balance`
itself (the model kind's physics lives in the candidate's model)."""
from __future__ import annotations

import ast
from pathlib import Path

import jointcal.discrepancy

PACKAGE = Path(jointcal.discrepancy.__file__).parent


def _trees() -> dict[str, ast.Module]:
    return {p.stem: ast.parse(p.read_text()) for p in sorted(PACKAGE.glob("*.py"))}


def _imports(tree: ast.Module) -> set[str]:
    """The package's own modules a module imports (``from .x import ...``, ``from . import x``; under
    TYPE_CHECKING too)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            out |= {node.module.split(".")[0]} if node.module else {a.name for a in node.names}
    return out


def test_no_two_discrepancy_modules_import_each_other():
    imports = {name: _imports(tree) for name, tree in _trees().items()}
    assert len(imports) > 10 and "decay_readout" in imports["decays"]  # the walk sees the package
    mutual = sorted({tuple(sorted((a, b))) for a, deps in imports.items() for b in deps
                     if a != "__init__" and b in imports and a in imports[b]})
    assert not mutual, mutual


def test_the_package_names_no_level_g_and_calls_no_harmonic_balance():
    for name, tree in _trees().items():
        names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        names |= {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
        names |= {a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) for a in n.names}
        strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
        assert "harmonic_balance" not in names, name
        assert "level_g" not in names and "level_g" not in strings, name
