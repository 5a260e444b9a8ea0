"""What wirecheck tells a user names its modules as ``wirecheck.core.x``, never as a path ``core/x.py``:
a user's project often has its own ``core/`` and ``oracles/`` (issue 26, rough edge 4)."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PATH_NAME = re.compile(r"\b(?:core|oracles)/[\w/]*\.py\b")


def _docstrings(tree) -> set[int]:
    """ids of the docstring constants (a module's, class's or function's first statement)."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                found.add(id(body[0].value))
    return found


def test_no_string_a_user_can_read_names_a_module_by_its_path():
    offenders, strings = [], 0
    for path in sorted([*(ROOT / "core").rglob("*.py"), *(ROOT / "oracles").rglob("*.py")]):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docs = _docstrings(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
                strings += 1
                if PATH_NAME.search(node.value):
                    offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value[:80]!r}")
    assert strings > 1000  # the sources were read
    assert not offenders, "\n".join(offenders)
