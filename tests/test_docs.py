"""The front door and the documentation stay true without building the site.

- README.md fits on two screens and starts with the two set-up commands (CI runs the
  second one exactly);
- every relative link of README.md and docs/**/*.md points at a file that exists;
- every path such as ``mocap/io/trc.py`` or ``dynamics/scenes/`` named in the README, the
  docs, the examples or the packages' sources exists, and so does every module or object a
  docstring cross-references (``:func:`mocap.body.segments.default_skeleton```) or a doc
  page names in backticks (``mocap.rotations.angles.joint_angles``);
- no docstring or page cites the internal design document's section numbers;
- every page is in the site's navigation, and the navigation names no missing page.

``mkdocs build --strict`` (CI, after the tests) checks the links between pages again and
the API reference; these tests need no mkdocs.
"""
from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SETUP = [
    'python3 -m venv .venv && .venv/bin/pip install . && .venv/bin/mocap demo',
    'python3 -m venv .venv && .venv/bin/pip install ".[test,distributed,interop]" '
    '&& .venv/bin/python -m pytest -q',
]
PACKAGES = ("mocap", "synthesis", "dynamics")


def markdown_files() -> list[Path]:
    return [README, *sorted((ROOT / "docs").rglob("*.md"))]


def source_files() -> list[Path]:
    return sorted(p for folder in (*PACKAGES, "examples") for p in (ROOT / folder).rglob("*.py"))


def prose(text: str) -> str:
    """Markdown without its fenced code blocks (links there are not links)."""
    return re.sub(r"^(```|~~~).*?^\1", "", text, flags=re.S | re.M)


# ---------------------------------------------------------------- README

def test_readme_is_short_and_starts_with_the_two_setup_commands():
    lines = README.read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; the front door keeps to 200"
    assert lines[0].startswith("# ")
    body = [line for line in lines[1:] if line.strip()]
    assert body[0].startswith("```") and body[1:3] == SETUP and body[3] == "```", body[:4]
    # CI runs the README's test command exactly
    assert SETUP[1] in (ROOT / ".ci" / "run").read_text().splitlines()


def test_readme_quick_start_runs(tmp_path):
    text = README.read_text(encoding="utf-8")
    blocks = re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)
    assert len(blocks) == 1 and len(blocks[0].splitlines()) <= 12
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-c", blocks[0]], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # what it prints is true: the file it wrote, and the knee of a walk
    frames, rate, knee = re.fullmatch(r"(\d+) frames at (\d+) Hz; knee flexion up to (\d+)°\n",
                                      done.stdout).groups()
    assert (tmp_path / "walk.c3d").is_file() and int(frames) > 50 and int(rate) == 100
    assert 45 < int(knee) < 80


# ---------------------------------------------------------------- links

LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def broken_links(path: Path) -> list[str]:
    """Relative link targets of a markdown file that do not exist."""
    found = []
    for target in LINK.findall(prose(path.read_text(encoding="utf-8"))):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue                                   # http:, mailto:, an anchor here
        file = target.split("#", 1)[0]
        if not (path.parent / file).exists():
            found.append(target)
    return found


@pytest.mark.parametrize("path", markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_point_at_files_that_exist(path):
    assert broken_links(path) == []


def test_the_link_check_finds_a_broken_link(tmp_path):
    (tmp_path / "there.md").write_text("x")
    page = tmp_path / "page.md"
    page.write_text("[ok](there.md) [ok](there.md#a) [web](https://x.org) [anchor](#top)\n"
                    "![gone](images/gone.png) and [moved](../old/place.md#part)\n"
                    "```\n[in code](not/a/link.md)\n```\n")
    assert broken_links(page) == ["images/gone.png", "../old/place.md#part"]


# ---------------------------------------------------------------- paths and names

PATH = re.compile(r"(?<![\w./~-])((?:mocap|synthesis|dynamics|tests|examples)/[\w./-]*[\w/])")


def missing_paths(text: str) -> list[str]:
    """Path-like mentions (``mocap/io/trc.py``, ``dynamics/scenes/``) that do not exist."""
    found = []
    for path in PATH.findall(text):
        if path.endswith(".py") or path.endswith("/"):
            if not (ROOT / path).exists():
                found.append(path)
    return found


@pytest.mark.parametrize("path", markdown_files() + source_files(),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_named_paths_exist(path):
    assert missing_paths(path.read_text(encoding="utf-8")) == []


@lru_cache(maxsize=None)
def _module_file(dotted: str) -> Path | None:
    base = ROOT.joinpath(*dotted.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


@lru_cache(maxsize=None)
def _names(path: Path, cls: str | None = None) -> frozenset:
    """Names defined at the top of a module (or in one of its classes)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    body = tree.body
    if cls is not None:
        body = next((node.body for node in tree.body
                     if isinstance(node, ast.ClassDef) and node.name == cls), [])
    names = set()
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
            if any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
                names.update(c.value for c in ast.walk(node.value)     # lazily loaded names
                             if isinstance(c, ast.Constant) and isinstance(c.value, str))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, ast.If):                    # TYPE_CHECKING blocks and the like
            names.update(n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.ClassDef)))
    for node in ast.walk(tree) if cls is None else ():
        # lazily provided names: ``if name == "Trial"`` / ``in ("A", "B")`` in __getattr__
        if isinstance(node, ast.FunctionDef) and node.name == "__getattr__":
            names.update(c.value for c in ast.walk(node)
                         if isinstance(c, ast.Constant) and isinstance(c.value, str))
    return frozenset(names)


def resolves(dotted: str) -> bool:
    """Whether ``dotted`` names a module of this project, or a name defined in one."""
    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        module = _module_file(".".join(parts[:split]))
        if module is None:
            continue
        rest = parts[split:]
        if not rest:
            return True
        if rest[0] not in _names(module):
            return False
        return len(rest) == 1 or rest[1] in _names(module, rest[0]) or len(rest) > 2
    return False


ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|exc|obj):`~?((?:mocap|synthesis|dynamics)"
                  r"(?:\.\w+)+)`")
BACKTICKED = re.compile(r"`((?:mocap|synthesis|dynamics)(?:\.[A-Za-z_]\w*)+)(?:\(\))?`")


def unresolved_names(text: str, pattern: re.Pattern) -> list[str]:
    return [name for name in pattern.findall(text) if not resolves(name)]


@pytest.mark.parametrize("path", source_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_docstring_cross_references_resolve(path):
    assert unresolved_names(path.read_text(encoding="utf-8"), ROLE) == []


@pytest.mark.parametrize("path", markdown_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_modules_and_functions_named_in_the_docs_exist(path):
    text = path.read_text(encoding="utf-8")
    names = BACKTICKED.findall(text) + re.findall(r"^::: ([\w.]+)", text, flags=re.M)
    assert [name for name in names if not resolves(name)] == []


def test_the_path_and_name_checks_find_stale_mentions():
    text = ("see mocap/io/trc.py and mocap/plugingait.py, dynamics/scenes/ and dynamics/scene/, "
            "../shared/realdata/x/mocap/nothing.py is someone else's")
    assert missing_paths(text) == ["mocap/plugingait.py", "dynamics/scene/"]
    assert resolves("mocap.body.segments.default_skeleton")
    assert resolves("mocap.rotations.angles.JointAngles.segment")
    assert resolves("mocap.Trial")                        # provided lazily by __getattr__
    assert resolves("mocap.clean.fill_gaps")              # in __all__, loaded on first use
    assert not resolves("mocap.skeleton.default_skeleton")     # moved to mocap.body.segments
    assert not resolves("mocap.rotations.angles.JointAngles.no_such_method")
    assert not resolves("dynamics.anthropometry.foot_points")
    assert unresolved_names(":func:`~mocap.plugingait.Subject` and :class:`mocap.trial.Trial`",
                            ROLE) == ["mocap.plugingait.Subject"]


# ---------------------------------------------------------------- design section numbers

SECTION = re.compile(r"DESIGN(?:\.md)?,?\s*(?:section\s*|§\s*)?\d")


@pytest.mark.parametrize("path", markdown_files() + source_files(),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_internal_design_section_numbers(path):
    assert SECTION.findall(path.read_text(encoding="utf-8")) == []


def test_the_section_check_finds_one():
    assert SECTION.findall("the JSON object (DESIGN 3.5) and DESIGN.md §3.2") != []
    assert SECTION.findall("(Vasilescu 2002, §3); see docs/formats/check-json.md") == []


# ---------------------------------------------------------------- site navigation

def test_every_page_is_in_the_navigation_and_every_entry_exists():
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    nav = config[config.index("\nnav:"):]
    listed = set(re.findall(r"^\s*-\s*(?:[^:\n]+:\s*)?([\w/.-]+\.md)\s*$", nav, flags=re.M))
    pages = {str(p.relative_to(ROOT / "docs")) for p in (ROOT / "docs").rglob("*.md")}
    assert listed - pages == set(), "navigation entries without a page"
    assert pages - listed == set(), "pages missing from the navigation"
