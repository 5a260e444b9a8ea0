"""The package's internal imports, measured: how many, how many inside functions, how many take another
module's ``_private`` name, and the import cycles (strongly connected components of grimp's graph).

    python benchmarks/import_graph.py                 # this tree
    python benchmarks/import_graph.py /work/main .    # two trees side by side (before / after)

The import contract itself (layers, no cycles) is pyproject.toml's ``[tool.importlinter]``, checked by
``lint-imports`` in .ci/run; tests/test_import_contract.py runs these counts' checks on the tree and on
copies of it with an upward import, a cycle or a private name added.

An *internal import* is an ``import``/``from ... import`` statement of the package's own modules
(relative, or ``wirecheck.*``), in ``__init__.py``, ``core/`` or ``oracles/``; *inside a function*: its
statement is in a function's body. A *private name* is one starting with a single ``_``, imported from
another module or read as ``module._name`` off an internal module imported by name.
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

PACKAGE = "wirecheck"


@dataclass(frozen=True)
class InternalImport:
    """One internal import statement: where it is, what it names, whether it sits in a function."""

    file: str
    line: int
    module: str  # as written: ".judge.metrics", "wirecheck.core.errors"
    names: tuple[str, ...]
    in_function: bool


def package_files(root: Path) -> list[Path]:
    """The package's source files under the tree ``root``: the root ``__init__.py``, ``core/``, ``oracles/``."""
    root = Path(root)
    return [root / "__init__.py", *sorted(root.glob("core/**/*.py")), *sorted(root.glob("oracles/**/*.py"))]


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def internal_imports(root: Path) -> list[InternalImport]:
    """Every internal import statement of the tree ``root`` (module docstring)."""
    out = []
    for path in package_files(root):
        rel = str(path.relative_to(root))

        def walk(node, in_function: bool):
            for child in ast.iter_child_nodes(node):
                inner = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                if isinstance(child, ast.ImportFrom) and (child.level or (child.module or "").startswith(PACKAGE)):
                    out.append(
                        InternalImport(
                            rel,
                            child.lineno,
                            "." * child.level + (child.module or ""),
                            tuple(a.name for a in child.names),
                            in_function,
                        )
                    )
                elif isinstance(child, ast.Import):
                    for alias in child.names:
                        if alias.name == PACKAGE or alias.name.startswith(PACKAGE + "."):
                            out.append(InternalImport(rel, child.lineno, alias.name, (), in_function))
                walk(child, inner)

        walk(ast.parse(path.read_text(), filename=rel), False)
    return out


def private_name_uses(root: Path) -> list[str]:
    """``file:line: how`` for each private name of another module imported or read off an imported module."""
    found = []
    for path in package_files(root):
        rel = str(path.relative_to(root))
        tree = ast.parse(path.read_text(), filename=rel)
        modules = set()  # internal modules bound to a name here
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith(PACKAGE)):
                for alias in node.names:
                    if _is_private(alias.name):
                        found.append(
                            f"{rel}:{node.lineno}: from {'.' * node.level}{node.module or ''} import {alias.name}"
                        )
                    modules.add(alias.asname or alias.name)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name.startswith(PACKAGE):
                        modules.add(alias.asname or alias.name.split(".")[0])
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id in modules
                and _is_private(node.attr)
            ):
                found.append(f"{rel}:{node.lineno}: {node.value.id}.{node.attr}")
    return sorted(found)


_CYCLES = r"""
import json, sys
import grimp
graph = grimp.build_graph(sys.argv[1], cache_dir=None)
index, low, stack, on_stack, cycles = {}, {}, [], set(), []
sys.setrecursionlimit(10000)
def visit(v):
    index[v] = low[v] = len(index); stack.append(v); on_stack.add(v)
    for w in graph.find_modules_directly_imported_by(v):
        if w not in index:
            visit(w); low[v] = min(low[v], low[w])
        elif w in on_stack:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        scc = []
        while True:
            w = stack.pop(); on_stack.discard(w); scc.append(w)
            if w == v:
                break
        if len(scc) > 1:
            cycles.append(sorted(scc))
for m in sorted(graph.modules):
    if m not in index:
        visit(m)
print(json.dumps({"modules": len(graph.modules), "cycles": sorted(cycles)}))
"""


def import_cycles(root: Path) -> dict:
    """``{"modules": n, "cycles": [[module, ...], ...]}``: grimp's graph of the tree ``root`` (imports inside
    functions and under TYPE_CHECKING included), its strongly connected components of more than one module.

    The tree is imported as ``wirecheck`` from a temporary folder linking to it, in a child process.
    """
    with tempfile.TemporaryDirectory() as tmp:
        os.symlink(Path(root).resolve(), Path(tmp) / PACKAGE)
        env = dict(os.environ, PYTHONPATH=tmp)
        done = subprocess.run(
            [sys.executable, "-c", _CYCLES, PACKAGE], env=env, cwd=tmp, capture_output=True, text=True, timeout=300
        )
    if done.returncode != 0:
        raise RuntimeError(f"grimp on {root}: {done.stderr.strip().splitlines()[-1:]}")
    return json.loads(done.stdout)


def measure(root: Path) -> dict:
    imports = internal_imports(root)
    graph = import_cycles(root)
    return {
        "tree": str(root),
        "modules": graph["modules"],
        "internal_imports": len(imports),
        "inside_functions": sum(i.in_function for i in imports),
        "private_names": len(private_name_uses(root)),
        "cycles": len(graph["cycles"]),
        "modules_in_cycles": sum(len(c) for c in graph["cycles"]),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("trees", nargs="*", default=["."], help="source trees (repository roots); default: .")
    parser.add_argument("--list", action="store_true", help="also list the cycles and the private names")
    args = parser.parse_args(argv)
    for tree in args.trees:
        m = measure(Path(tree))
        print(
            f"{m['tree']}: {m['modules']} modules; {m['internal_imports']} internal imports, "
            f"{m['inside_functions']} inside functions; {m['private_names']} private names of other modules; "
            f"{m['cycles']} import cycles ({m['modules_in_cycles']} modules)"
        )
        if args.list:
            for cycle in import_cycles(Path(tree))["cycles"]:
                print("  cycle:", " ".join(c.removeprefix(PACKAGE + ".") for c in cycle))
            for use in private_name_uses(Path(tree)):
                print("  private:", use)
    return 0


if __name__ == "__main__":
    sys.exit(main())
