"""The house in layers (docs/design.md section 6): every import points downward, and no two modules import
each other, directly or through others.

- ``import-linter`` checks the layers contract of ``.importlinter`` (core < twin < definitions < materials < lights
  < scene < shaders < gpu < checks < evaluation < testing < analysis < formats < batch, integrations < bench
  < tools), counting imports at module level and inside functions alike;
- an independent walk over every module's syntax tree counts import cycles among glphong's modules (zero),
  and imports inside functions (none but the optional dependencies' and the moved-path finder's).
"""
import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "glphong"


def _module_name(path):
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _graph():
    """``(edges, in_function)``: module -> glphong modules it imports (anywhere), and those imported inside
    a function."""
    modules = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    edges, in_function = {m: set() for m in modules}, {m: set() for m in modules}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top = {id(node) for node in tree.body}
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1] + ([base] if base else []))
                subs = [f"{base}.{a.name}" for a in node.names if f"{base}.{a.name}" in modules]
                targets = subs + ([base] if len(subs) < len(node.names) else [])
            else:
                continue
            for target in targets:
                while target not in modules and "." in target:
                    target = target.rpartition(".")[0]
                if target in modules and target != name and target.startswith("glphong"):
                    edges[name].add(target)
                    if id(node) not in top:
                        in_function[name].add(target)
    return edges, in_function


def _cycles(edges):
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, out, counter = {}, {}, set(), [], [], [0]
    for start in edges:
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        out.append(sorted(component))
    return out


def test_no_import_cycles():
    edges, _ = _graph()
    assert len(edges) > 60
    assert _cycles(edges) == []


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_imports_sit_at_the_top_of_modules():
    _, in_function = _graph()
    assert {m: sorted(t) for m, t in in_function.items() if t} == {}


def test_layers_contract():
    pytest.importorskip("importlinter", reason="import-linter is in the [test] extra")
    result = subprocess.run([sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command; "
                             "sys.exit(lint_imports_command())"], cwd=ROOT, capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0 and "1 kept, 0 broken" in result.stdout, result.stdout[-3000:] + result.stderr[-2000:]


def test_every_module_is_in_a_layer():
    """A new subpackage must be placed in the contract, else its imports go unchecked."""
    config = (ROOT / ".importlinter").read_text(encoding="utf-8")
    packages = {p.parent.name for p in PACKAGE.glob("*/__init__.py")} - {"glsl"}
    missing = sorted(p for p in packages if f"glphong.{p}" not in config)
    assert missing == []


def test_every_package_is_installed():
    """setup.cfg lists its packages by name: a subpackage missing there would be missing from the wheel."""
    listed = (ROOT / "setup.cfg").read_text(encoding="utf-8").split("packages =", 1)[1].split("package_dir", 1)[0].split()
    folders = sorted(_module_name(p.parent / "__init__.py") for p in PACKAGE.rglob("__init__.py"))
    assert sorted(set(folders) - set(listed)) == []


def test_optional_dependencies_are_imported_only_where_used():
    """Imports at the top of modules must not pull an optional extra into ``import glphong`` or the command
    line: with pyrender, matplotlib, tqdm, Dask, DracoPy, pytest and the docs tools unimportable, they import."""
    code = ("import sys\n"
            "class Block:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] in ('pyrender', 'matplotlib', 'tqdm', 'distributed', 'dask', 'DracoPy', 'embreex',\n"
            "                                  'importlinter', 'pytest', 'hypothesis', 'sphinx'):\n"
            "            raise ImportError('blocked ' + name)\n"
            "sys.meta_path.insert(0, Block())\n"
            "import glphong, glphong.tools.cli, glphong.batch, glphong.formats, glphong.analysis\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pyrender', 'matplotlib', 'pytest')))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip() == "[]"
