"""The packages' layers, read from the source: every import, top-level or inside a function.

- ``mocap`` is the base: nothing under ``mocap/`` outside its command shell ``mocap/cli/``
  imports ``synthesis`` or ``dynamics``;
- ``synthesis`` never imports ``dynamics`` (both build on ``mocap`` only);
- nothing imports ``mocap.cli`` (the shell sits on top; only ``mocap/__main__.py``, the
  ``python -m mocap`` entry point, starts it);
- no two modules import each other, directly or around a longer circle;
- inside ``mocap``, the sub-packages are layers (:data:`MOCAP_LAYERS`: plumbing, containers,
  cleaning, marker sets, rotations, the body, file formats, then the models and recipes, then
  the shell) and no module imports a module of a higher layer;
- the top of ``mocap/`` holds only the containers and the plumbing (:data:`LOOSE_MODULES`):
  every other job lives in a sub-package named after it;
- no module is longer than :data:`MAX_MODULE_LINES` lines.

The checks are functions of an import graph, so the tests below run them both on the real
tree and on graphs with a planted violation (each check must be able to fail).
"""
from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("mocap", "synthesis", "dynamics")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def project_modules() -> dict[str, Path]:
    """Dotted name -> file of every module of the three packages."""
    return {module_name(p): p for package in PACKAGES for p in (ROOT / package).rglob("*.py")}


def imports_of(path: Path, name: str, known: set[str]) -> set[str]:
    """Project modules that ``path`` imports anywhere (functions included), resolved to the
    deepest known module (``from mocap.io import read`` -> ``mocap.io``;
    ``from mocap.io import bvh`` -> ``mocap.io.bvh``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else base
                       for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


@functools.lru_cache(maxsize=1)
def _parsed_graph() -> tuple[tuple[str, frozenset[str]], ...]:
    modules = project_modules()
    known = set(modules)
    return tuple((name, frozenset(imports_of(path, name, known)))
                 for name, path in modules.items())


def import_graph() -> dict[str, set[str]]:
    """Module -> the project modules it imports (a fresh copy: tests may plant edges)."""
    return {name: set(targets) for name, targets in _parsed_graph()}


def _inside(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


#: The layers of ``mocap``, lowest first: a module may import its own layer and those below.
MOCAP_LAYERS: tuple[tuple[str, ...], ...] = (
    ("mocap.errors", "mocap.atomic", "mocap.progress", "mocap.tomlfile", "mocap.batch",
     "mocap.budget", "mocap.resources"),
    ("mocap.trial", "mocap.skeleton"),
    ("mocap.clean",),
    ("mocap.markersets",),
    ("mocap.rotations",),
    ("mocap.body",),
    ("mocap.io",),
    ("mocap.plugingait", "mocap.synthetic", "mocap.pipeline", "mocap.summary", "mocap.plot",
     "mocap.view"),
    # the package's own namespace re-exports from every layer (``mocap.Trial``)
    ("mocap.cli", "mocap.__main__", "mocap"),
)

#: The only modules allowed at the top of ``mocap/``: containers and plumbing.
LOOSE_MODULES = frozenset({"__init__", "__main__", "trial", "skeleton", "errors", "atomic",
                           "progress", "tomlfile", "budget", "resources", "batch", "pipeline",
                           "summary", "plot"})

#: The longest module allowed, lines.
MAX_MODULE_LINES = 600


def mocap_layer(module: str) -> int | None:
    """Index of the :data:`MOCAP_LAYERS` entry ``module`` belongs to (None outside mocap or
    in no listed layer)."""
    for rank, members in enumerate(MOCAP_LAYERS):
        if any(module == m or (m != "mocap" and module.startswith(m + "."))
               for m in members):
            return rank
    return None


def upward_imports(graph: dict[str, set[str]]) -> list[str]:
    """Imports inside ``mocap`` from a lower layer to a higher one, and modules of
    ``mocap`` that belong to no layer."""
    problems = []
    for module, targets in sorted(graph.items()):
        if not _inside(module, "mocap"):
            continue
        rank = mocap_layer(module)
        if rank is None:
            problems.append(f"{module} belongs to no layer of MOCAP_LAYERS")
            continue
        for target in sorted(targets):
            target_rank = mocap_layer(target)
            if target_rank is not None and target_rank > rank:
                problems.append(f"{module} imports {target}: a higher layer")
    return problems


def stray_modules(names: list[str]) -> list[str]:
    """Files at the top of ``mocap/`` (stems) that are not containers or plumbing."""
    return sorted(set(names) - LOOSE_MODULES)


def long_modules(lengths: dict[str, int]) -> list[str]:
    """Modules longer than :data:`MAX_MODULE_LINES`, with their length."""
    return [f"{name}: {count} lines" for name, count in sorted(lengths.items())
            if count > MAX_MODULE_LINES]


def layer_violations(graph: dict[str, set[str]]) -> list[str]:
    """Every import that breaks the layering rules of the module docstring."""
    problems = []
    for module, targets in sorted(graph.items()):
        for target in sorted(targets):
            if (_inside(module, "mocap") and not _inside(module, "mocap.cli")
                    and (_inside(target, "synthesis") or _inside(target, "dynamics"))):
                problems.append(f"{module} imports {target}: only mocap.cli may")
            if _inside(module, "synthesis") and _inside(target, "dynamics"):
                problems.append(f"{module} imports {target}: synthesis never imports dynamics")
            if (_inside(target, "mocap.cli") and not _inside(module, "mocap.cli")
                    and module != "mocap.__main__"):
                problems.append(f"{module} imports {target}: nothing imports the shell")
    return problems


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []
    counter = [0]

    def visit(node: str) -> None:
        index[node] = low[node] = counter[0]
        counter[0] += 1
        stack.append(node)
        on_stack.add(node)
        for target in graph.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                circles.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return circles


# ------------------------------------------------------------------ the real tree

def test_the_tree_keeps_its_layers():
    assert layer_violations(import_graph()) == []


def test_no_two_modules_import_each_other():
    assert import_circles(import_graph()) == []


def test_mocap_imports_only_downwards():
    assert upward_imports(import_graph()) == []


def test_the_top_of_mocap_holds_only_containers_and_plumbing():
    assert stray_modules([p.stem for p in (ROOT / "mocap").glob("*.py")]) == []


def test_no_module_is_too_long():
    lengths = {name: len(path.read_text(encoding="utf-8").splitlines())
               for name, path in project_modules().items()}
    assert long_modules(lengths) == []


def test_a_planted_upward_import_is_caught():
    graph = import_graph()
    graph["mocap.rotations.euler"] = graph["mocap.rotations.euler"] | {"mocap.io.bvh"}
    assert any("mocap.rotations.euler imports mocap.io.bvh" in p for p in upward_imports(graph))
    graph["mocap.newthing"] = set()
    assert "mocap.newthing belongs to no layer of MOCAP_LAYERS" in upward_imports(graph)


def test_a_planted_loose_module_and_a_long_one_are_caught():
    assert stray_modules(["trial", "errors", "euler"]) == ["euler"]
    assert long_modules({"mocap.trial": 600, "mocap.big": 601}) == ["mocap.big: 601 lines"]


def test_the_graph_sees_imports_inside_functions():
    graph = import_graph()
    # mocap.cli.synthesis imports synthesis modules; the shell is where all three meet
    assert any(_inside(t, "synthesis") for t in graph["mocap.cli.synthesis"])
    assert "mocap.errors" in graph["mocap.io"]


# ------------------------------------------------------------------ planted violations

@pytest.mark.parametrize("module, target", [
    ("mocap.rotations.angles", "dynamics.humanoid"),        # the base reaching up
    ("mocap.io.bvh", "synthesis.model"),
    ("synthesis.model", "dynamics.sim.system"),   # synthesis reaching sideways
    ("dynamics.secondary", "mocap.cli"),          # importing the shell
])
def test_a_planted_import_is_caught(module, target):
    graph = import_graph()
    graph.setdefault(module, set()).add(target)
    assert any(f"{module} imports {target}" in p for p in layer_violations(graph))


def test_a_planted_circle_is_caught():
    graph = import_graph()
    graph["mocap.trial"] = graph["mocap.trial"] | {"mocap.rotations.angles"}   # angles imports trial
    assert any({"mocap.trial", "mocap.rotations.angles"} <= set(c) for c in import_circles(graph))


def test_a_planted_import_in_a_file_is_parsed(tmp_path):
    source = tmp_path / "planted.py"
    source.write_text("def late():\n    from dynamics.humanoid import check\n")
    known = set(project_modules())
    found = imports_of(source, "mocap.planted", known)
    assert any(_inside(t, "dynamics.humanoid") for t in found)
    assert layer_violations({"mocap.planted": found})


def test_the_shell_uses_only_argparse_public_api():
    """argparse's private attributes (``_actions``, ``_subparsers``, ``_SubParsersAction``)
    change between Python versions; the shell keeps its own table of options and
    sub-commands (``_Parser.flags``, ``_Parser.commands``)."""
    import re
    private = re.compile(r"\._(actions|subparsers|group_actions|option_string_actions|"
                         r"SubParsersAction|registries|defaults)\b")
    found = [f"{path.relative_to(ROOT)}:{number}"
             for path in sorted((ROOT / "mocap" / "cli").glob("*.py"))
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if private.search(line)]
    assert found == []
    assert private.search("parser._actions") and private.search("argparse._SubParsersAction")


def test_pyproject_installs_every_package_and_the_data():
    """pyproject.toml lists the packages (the top-level data/ installs as mocap.data, which
    a find directive cannot map): a new package missing from the list would not install."""
    import tomllib

    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]
    listed = set(config["setuptools"]["packages"])
    found = {module_name(init) for package in PACKAGES
             for init in (ROOT / package).rglob("__init__.py")}
    assert listed - {"mocap.data"} == found
    assert config["setuptools"]["package-dir"]["mocap.data"] == "data"
    shipped = {p.relative_to(ROOT / "data").as_posix() for p in (ROOT / "data").rglob("*")
               if p.is_file() and "__pycache__" not in p.parts}
    patterns = config["setuptools"]["package-data"]["mocap.data"]
    import fnmatch
    assert all(any(fnmatch.fnmatch(name, pattern) for pattern in patterns) for name in shipped)
    assert {"markersets/synthetic15.toml", "scenes/hanging-cloth.toml",
            "bodies/de-leva-1996.toml"} <= shipped
