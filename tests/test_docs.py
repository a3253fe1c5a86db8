"""The docs never contradict the code: generated tables up to date, every link resolves.

- The pages with generated regions (docs/generate.py, ``make docs``) equal what the script
  writes from the code's own tables.
- Every relative link and image of README.md and docs/*.md points to a file that exists,
  and an anchor (``page.md#heading``) to a heading of that page (GitHub's slugs).
- Every ``docs/...`` or ``config/...`` path named in a comment of config/ or in the source,
  tests and benchmarks exists (with its anchor).
- Every file the docs name in code (``model/session.py``, ``fig8b.yaml``) exists, and every
  ``path.py::name`` (the equation table of docs/model.md) is a function, class or constant
  of that file.
- config/sim.yaml sets only parameters that sim_node has, each to a value it accepts.
"""

from __future__ import annotations

import ast
import importlib.util
import re
import unicodedata
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# Pages other branches are writing at the time of this test; a link to one of them may
# point nowhere until it is merged (then it is checked like any other). Remove names here
# once their page exists.
PAGES_IN_PROGRESS: set[str] = set()
README_MAX_LINES = 200

FENCE = re.compile(r"^[ \t]*(```|~~~).*?^[ \t]*\1", re.MULTILINE | re.DOTALL)
CODE_SPAN = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_SRC = re.compile(r"<(?:img|a)\s[^>]*?(?:src|href)=\"([^\"]+)\"")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)
REPO_PATH = re.compile(r"\b((?:docs|config|drill_sim_ros|tests|benchmarks)/[\w./-]*\w)"
                       r"(#[\w-]+)?")
CODE_REF = re.compile(r"`([\w/]+\.py)::([\w.]+)`")
FILE_NAME = re.compile(r"`([\w./-]+\.(?:py|yaml|md|xml|mjs))(?:::[\w.]+)?`")
SOURCE_DIRS = ("drill_sim_ros", "tests", "benchmarks")


def _load_generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location("docs_generate", ROOT / "docs" / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# ---- GitHub's heading anchors ---------------------------------------------------------------

def slug(heading: str) -> str:
    """GitHub's anchor of a heading: the rendered text, lower case, punctuation dropped
    (except - and _), spaces to hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)     # links: their text
    text = text.replace("`", "").replace("*", "")
    text = "".join(c for c in text.lower()
                   if c in " -_" or unicodedata.category(c)[0] in "LN")
    return text.replace(" ", "-")


def anchors(text: str) -> set[str]:
    """Every anchor of a page, with GitHub's -1, -2 suffixes for repeated headings."""
    found: set[str] = set()
    seen: dict[str, int] = {}
    for heading in HEADING.findall(FENCE.sub("", text)):
        base = slug(heading)
        count = seen.get(base, 0)
        seen[base] = count + 1
        found.add(base if count == 0 else f"{base}-{count}")
    found.update(re.findall(r"<a\s+(?:id|name)=\"([^\"]+)\"", text))
    return found


# ---- what a page links to ------------------------------------------------------------------

def links(text: str) -> list[str]:
    """The targets of the Markdown links and images of ``text``, outside code."""
    prose = CODE_SPAN.sub("", FENCE.sub("", text))
    return LINK.findall(prose) + HTML_SRC.findall(prose)


def broken_links(page: Path, root: Path = ROOT,
                 in_progress: frozenset[str] | set[str] = frozenset()) -> list[str]:
    """Each relative link of ``page`` that does not resolve, as 'target: why'."""
    problems = []
    for target in links(page.read_text(encoding="utf-8")):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):          # http:, https:, mailto:
            continue
        path_part, _, anchor = target.partition("#")
        dest = (page.parent / path_part).resolve() if path_part else page
        problems += _problem(target, dest, anchor, root, in_progress)
    return problems


def _problem(target: str, dest: Path, anchor: str, root: Path,
             in_progress: frozenset[str] | set[str]) -> list[str]:
    try:
        relative = dest.resolve().relative_to(root.resolve()).as_posix()
    except ValueError:
        return [f"{target}: outside the repository"]
    if not dest.exists():
        return [] if relative in in_progress else [f"{target}: no such file"]
    if anchor and dest.suffix == ".md" and anchor not in anchors(dest.read_text("utf-8")):
        return [f"{target}: {relative} has no heading #{anchor}"]
    return []


def broken_repo_paths(text: str, root: Path = ROOT) -> list[str]:
    """Each repository path named in ``text`` (a comment, a docstring) that does not exist."""
    problems = []
    for path_part, anchor in REPO_PATH.findall(text):
        problems += _problem(path_part + anchor, root / path_part, anchor.lstrip("#"), root,
                             PAGES_IN_PROGRESS)
    return problems


def yaml_comments(text: str) -> str:
    return "\n".join(line.split("#", 1)[1] for line in text.splitlines() if "#" in line)


# ---- code references --------------------------------------------------------------------------

def defines(source: str, dotted: str) -> bool:
    """Whether ``source`` defines ``dotted`` (a function, class or constant; Class.member)."""
    scope: list[ast.stmt] = ast.parse(source).body
    for part in dotted.split("."):
        match = next((node for node in scope if part in _name_of(node)), None)
        if match is None:
            return False
        scope = getattr(match, "body", [])
    return True


def _name_of(node: ast.stmt) -> set[str]:
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return {node.name}
    if isinstance(node, ast.Assign):
        return {t.id for t in node.targets if isinstance(t, ast.Name)}
    if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
        return {node.target.id}
    return set()


def missing_files(page: Path, root: Path = ROOT) -> list[str]:
    """Each file named in a code span of ``page`` that is nowhere it could mean: the
    repository root, the package or one of its folders, the page's folder, the presets."""
    folders = [root, root / "drill_sim_ros", page.parent, root / "config" / "presets",
               *sorted(p for p in (root / "drill_sim_ros").glob("*") if p.is_dir())]
    return [name for name in FILE_NAME.findall(page.read_text(encoding="utf-8"))
            if not any((folder / name).exists() for folder in folders)]


def broken_code_refs(text: str, root: Path = ROOT) -> list[str]:
    problems = []
    for path_part, name in CODE_REF.findall(text):
        candidates = [root / path_part, root / "drill_sim_ros" / path_part]
        path = next((p for p in candidates if p.is_file()), None)
        if path is None:
            problems.append(f"{path_part}::{name}: no such file")
        elif not defines(path.read_text(encoding="utf-8"), name):
            problems.append(f"{path_part}::{name}: not defined there")
    return problems


# ---- the tests ----------------------------------------------------------------------------

def test_generated_pages_are_up_to_date() -> None:
    generator = _load_generator()
    stale = [path.relative_to(ROOT).as_posix() for path, text in generator.expected_pages().items()
             if path.read_text(encoding="utf-8") != text]
    assert not stale, f"out of date, run `make docs`: {stale}"


def test_generated_tables_hold_every_parameter_and_topic() -> None:
    from drill_sim_ros import topics
    from drill_sim_ros.ros.parameters import SPECS

    page = (ROOT / "docs" / "sim_node.md").read_text(encoding="utf-8")
    for spec in SPECS:
        assert f"| `{spec.name}` |" in page
    for topic in topics.MSG_TYPES:
        assert f"| `{topic}` |" in page


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_link_resolves(page: Path) -> None:
    assert broken_links(page, in_progress=PAGES_IN_PROGRESS) == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_named_function_exists(page: Path) -> None:
    assert broken_code_refs(page.read_text(encoding="utf-8")) == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_named_file_exists(page: Path) -> None:
    assert missing_files(page) == []


def test_config_comments_point_to_what_exists() -> None:
    problems = []
    for path in sorted((ROOT / "config").rglob("*.yaml")):
        problems += [f"{path.name}: {p}"
                     for p in broken_repo_paths(yaml_comments(path.read_text("utf-8")))]
    for path in sorted((ROOT / "config").rglob("*.xml")):         # the Fast DDS profile
        comments = "\n".join(re.findall(r"<!--(.*?)-->", path.read_text("utf-8"), re.DOTALL))
        problems += [f"{path.name}: {p}" for p in broken_repo_paths(comments)]
    assert problems == []


def test_source_points_to_docs_that_exist() -> None:
    problems = []
    for folder in SOURCE_DIRS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path == Path(__file__).resolve():
                continue
            named = [m for m in REPO_PATH.finditer(path.read_text("utf-8"))
                     if m.group(1).startswith("docs/") and m.group(1).endswith(".md")]
            problems += [f"{path.relative_to(ROOT)}: {p}" for m in named
                         for p in broken_repo_paths(m.group(0))]
    assert problems == []


def test_readme_is_short() -> None:
    lines = (ROOT / "README.md").read_text(encoding="utf-8").count("\n")
    assert lines <= README_MAX_LINES


# ---- the checks themselves find what is wrong ----------------------------------------------

def test_checks_find_dead_links_and_anchors(tmp_path: Path) -> None:
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "a.md").write_text("# Title\n\n## The top drive (eq. 12)\n")
    page = tmp_path / "README.md"
    page.write_text("[ok](docs/a.md#the-top-drive-eq-12) ![img](docs/none.png) "
                    "[gone](docs/b.md) [bad](docs/a.md#nowhere) [self](#title-x) "
                    "[web](https://example.org/x) `[code](docs/c.md)`\n"
                    "```\n[fenced](docs/d.md)\n```\n  ```\n  [indented](docs/e.md)\n  ```\n"
                    "[wip](docs/wip.md)\n")
    assert broken_links(page, tmp_path, in_progress={"docs/wip.md"}) == [
        "docs/none.png: no such file", "docs/b.md: no such file",
        "docs/a.md#nowhere: docs/a.md has no heading #nowhere",
        "#title-x: README.md has no heading #title-x"]


def test_slugs_follow_github() -> None:
    assert slug("Gallery: the paper's figures from this model") == \
        "gallery-the-papers-figures-from-this-model"
    assert slug("The offline command: `drill_sim run`") == "the-offline-command-drill_sim-run"
    assert anchors("## Tests\n## Tests\n") == {"tests", "tests-1"}


def test_checks_find_missing_code_and_paths(tmp_path: Path) -> None:
    (tmp_path / "m.py").write_text("X = 1\n\nclass A:\n    def run(self):\n        pass\n\n"
                                   "def f():\n    pass\n")
    text = "`m.py::f` `m.py::A.run` `m.py::X` `m.py::g` `m.py::A.walk` `n.py::f`"
    assert broken_code_refs(text, tmp_path) == [
        "m.py::g: not defined there", "m.py::A.walk: not defined there",
        "n.py::f: no such file"]
    (tmp_path / "docs").mkdir()
    assert broken_repo_paths("see docs/none.md and docs", tmp_path) == [
        "docs/none.md: no such file"]
    (tmp_path / "drill_sim_ros" / "model").mkdir(parents=True)
    (tmp_path / "drill_sim_ros" / "model" / "kernel.py").write_text("")
    page = tmp_path / "docs" / "p.md"
    page.write_text("`kernel.py` `model/kernel.py` `m.py::f` `model/gone.py` `run.mcap`\n")
    assert missing_files(page, tmp_path) == ["model/gone.py"]


def test_generator_refuses_an_undescribed_topic_or_joint(monkeypatch: pytest.MonkeyPatch) -> None:
    from drill_sim_ros import topics

    generator = _load_generator()
    monkeypatch.setitem(topics.JOINTS, topics.SURFACE_MEASURED,
                        (*topics.MEASURED_JOINTS, "hook"))
    with pytest.raises(ValueError, match="JOINT_FIELDS"):
        generator.topic_table()
    monkeypatch.undo()
    monkeypatch.delitem(topics.DESCRIPTIONS, topics.CLOCK)
    with pytest.raises(ValueError, match="DESCRIPTIONS has no entry for /clock"):
        generator.topic_table()


def _flatten(tree: dict, prefix: str = "") -> dict[str, object]:
    flat: dict[str, object] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        flat.update(_flatten(value, name + ".") if isinstance(value, dict) else {name: value})
    return flat


def test_sim_yaml_sets_only_parameters_that_exist_with_valid_values() -> None:
    import yaml

    from drill_sim_ros.ros.parameters import SPEC_BY_NAME, validate

    tree = yaml.safe_load((ROOT / "config" / "sim.yaml").read_text(encoding="utf-8"))
    (node_key,) = tree                       # one node: drill_sim (in any namespace)
    values = _flatten(tree[node_key]["ros__parameters"])
    assert values, "config/sim.yaml sets no parameter"
    unknown = sorted(set(values) - set(SPEC_BY_NAME))
    assert unknown == [], f"config/sim.yaml sets parameters sim_node does not have: {unknown}"
    reasons = [validate(SPEC_BY_NAME[name], value) for name, value in values.items()]
    assert [r for r in reasons if r is not None] == []


def test_the_topic_table_says_keep_all_for_the_command_subscriptions() -> None:
    """The command subscriptions keep every command (docs/control-loop.md): the table must
    not show them as keep-last (rclpy gives a KEEP_ALL profile a depth of 10)."""
    from rclpy.qos import HistoryPolicy

    from drill_sim_ros import topics
    from drill_sim_ros.ros.sim_node import COMMAND_QOS

    assert COMMAND_QOS.history == HistoryPolicy.KEEP_ALL
    rows = {row.split(" | ")[0].strip("| `"): row
            for row in _load_generator().topic_table().splitlines()[2:]}
    for topic in topics.COMMANDS:
        assert "keep-all" in rows[topic] and "keep-last" not in rows[topic], rows[topic]


def test_every_ros2_run_or_param_in_the_docs_gives_the_venv_equivalent() -> None:
    """The venv has no ``ros2`` command (issue 22): within a few lines of each ``ros2 run``
    or ``ros2 param`` a page shows what works there (``.venv/bin/...``, ``drill_sim
    params``)."""
    pages = [ROOT / "README.md", ROOT / "config" / "sim.yaml", *sorted((ROOT / "docs").glob(
        "*.md"))]
    bare = []
    for page in pages:
        lines = page.read_text(encoding="utf-8").splitlines()
        for i, line in enumerate(lines):
            if re.search(r"ros2 (run|param)\b", line):
                near = "\n".join(lines[max(0, i - 8):i + 9])
                if ".venv/bin/" not in near and "drill_sim params" not in near:
                    bare.append(f"{page.relative_to(ROOT)}:{i + 1}")
    assert not bare, bare
