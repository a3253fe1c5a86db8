"""Every command block of the docs runs as written, or in the short form it states.

A fenced block (``bash``, ``sh``, ``shell`` or no language) of README.md or docs/*.md
whose first line starts with ``.venv/bin/drill_sim`` is run by ``bash -e`` (every command
must exit 0) in a fresh temporary directory holding links to this checkout's ``.venv``
(the venv running the tests), ``config`` and ``examples``: the paths the docs use resolve, and the
files the commands write land in the temporary directory. Each file a command names after
``--plot``, ``-o``, ``--out``, ``--trace``, ``--save-traces`` or ``--record`` must exist
afterwards. The selected blocks start together, two at a time (the rest of the suite keeps
one core of two busy).

A block that takes long states its short form in an HTML comment on the line right above
its fence (invisible on the rendered page), e.g.::

    <!-- short: --t-end 300 => --t-end 20; --ensemble 8 => --ensemble 2 -->

Each rule (``;`` or a new line between rules) is a literal text substitution applied to
the block before it runs, every occurrence; a rule that matches nothing fails the test, so
a stale rule cannot linger. The convention is described in docs/testing.md.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import textwrap
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COMMAND = ".venv/bin/drill_sim"
FENCE = re.compile(r"^([ \t]*)```([^`\n]*)\n(.*?)^\1```", re.MULTILINE | re.DOTALL)
SHELLS = ("", "bash", "sh", "shell")
SHORT = re.compile(r"<!--\s*short:((?:(?!-->).)*)-->\s*\Z", re.DOTALL)
OUTPUTS = re.compile(r"(?:^|\s)(?:--plot|-o|--out|--trace|--save-traces|--record)\s+(\S+)")
BLOCK_TIMEOUT_S = 240.0
PARALLEL_BLOCKS = 2


@dataclass(frozen=True)
class Block:
    """A command block: where it is, its text as written and its substitution rules."""

    page: str
    line: int
    text: str
    rules: tuple[tuple[str, str], ...]

    @property
    def short(self) -> str:
        """The block with its rules applied (each must match)."""
        text = self.text
        for old, new in self.rules:
            assert old in text, f"{self.page}:{self.line}: short-form rule {old!r} matches nothing"
            text = text.replace(old, new)
        return text


def _rules(comment: str) -> tuple[tuple[str, str], ...]:
    rules = []
    for rule in re.split(r"[;\n]", comment):
        if rule.strip():
            old, sep, new = rule.partition("=>")
            assert sep, f"short-form rule {rule.strip()!r} has no '=>'"
            rules.append((old.strip(), new.strip()))
    return tuple(rules)


def command_blocks(page: Path) -> list[Block]:
    """The page's shell blocks that start with ``.venv/bin/drill_sim``."""
    text = page.read_text(encoding="utf-8")
    blocks = []
    for match in FENCE.finditer(text):
        body = textwrap.dedent(match.group(3))
        if match.group(2).strip() not in SHELLS or not body.startswith(COMMAND):
            continue
        short = SHORT.search(text[:match.start()])
        name = page.relative_to(ROOT).as_posix() if page.is_relative_to(ROOT) else page.name
        blocks.append(Block(name,
                            text.count("\n", 0, match.start()) + 1, body,
                            _rules(short.group(1)) if short else ()))
    return blocks


BLOCKS = [block for page in PAGES for block in command_blocks(page)]


def _param(block: Block) -> pytest.param:
    marks = [pytest.mark.ros] if "--ros" in block.short else []
    return pytest.param(block, id=f"{block.page}:{block.line}", marks=marks)


def _workdir(tmp_path: Path) -> Path:
    """A directory where the docs' relative paths resolve: .venv, config and examples
    linked."""
    (tmp_path / ".venv").symlink_to(sys.prefix)
    (tmp_path / "config").symlink_to(ROOT / "config")
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    return tmp_path


def _run_block(block: Block, cwd: Path) -> tuple[Path, subprocess.CompletedProcess[str]]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])}
    done = subprocess.run(["bash", "-e", "-c", block.short], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=BLOCK_TIMEOUT_S,
                          stdin=subprocess.DEVNULL)
    return cwd, done


@pytest.fixture(scope="module")
def block_runs(request: pytest.FixtureRequest,
               tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Future]]:
    """The selected blocks, started at once, two at a time (the suite's own tests use one
    core of two): one future per block id."""
    if not (Path(sys.prefix) / "bin" / "drill_sim").exists():
        pytest.skip(f"{sys.prefix}/bin/drill_sim is not installed (make venv)")
    selected = [item.callspec.params["block"] for item in request.session.items
                if getattr(item, "originalname", "") == "test_command_block_runs"]
    with ThreadPoolExecutor(max_workers=PARALLEL_BLOCKS) as pool:
        yield {f"{b.page}:{b.line}": pool.submit(_run_block, b, _workdir(
            tmp_path_factory.mktemp("docs_block"))) for b in selected}


def test_the_docs_have_command_blocks() -> None:
    """The parser finds the blocks (a broken pattern would pass every page vacuously)."""
    pages = {block.page for block in BLOCKS}
    assert {"README.md", "docs/closed-loop.md", "docs/model.md", "docs/string.md",
            "docs/studies.md"} <= pages


def test_a_short_form_applies_its_rules_and_refuses_a_stale_one(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("Text.\n\n<!-- short: --t-end 300 => --t-end 20\n--json => -->\n"
                    "  ```bash\n  .venv/bin/drill_sim closed-loop --t-end 300 --json \\\n"
                    "      --plot a.png   # comment\n  ```\n\n```yaml\nx: 1\n```\n"
                    "```\n.venv/bin/drill_sim modes\n```\n```bash\nls\n```\n")
    first, second = command_blocks(page)
    assert (first.line, second.line, second.rules) == (5, 13, ())
    assert first.short == (".venv/bin/drill_sim closed-loop --t-end 20  \\\n"
                           "    --plot a.png   # comment\n")
    stale = Block("page.md", 5, first.text, (("--t-end 600", "--t-end 20"),))
    with pytest.raises(AssertionError, match="matches nothing"):
        _ = stale.short


@pytest.mark.parametrize("block", [_param(b) for b in BLOCKS])
def test_command_block_runs(block: Block, block_runs: dict[str, Future]) -> None:
    script = block.short
    cwd, done = block_runs[f"{block.page}:{block.line}"].result(timeout=2 * BLOCK_TIMEOUT_S)
    assert done.returncode == 0, (f"{block.page}:{block.line} exit {done.returncode}\n"
                                  f"{script}\n{done.stderr[-2000:]}")
    for line in script.replace("\\\n", " ").splitlines():
        words = " ".join(shlex.split(line, comments=True))
        for name in OUTPUTS.findall(words):
            assert (cwd / name).exists(), f"{block.page}:{block.line}: {name} not written"
