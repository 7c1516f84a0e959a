"""The README and the pages of docs/ hold what they promise.

Every Python example of README.md and docs/*.md runs as written, each in a fresh namespace of
its own process, except the few marked `<!-- not run: reason -->` on the line before them (they
need a user's data or a cluster). Every relative link and image of those pages points at a file
that exists, and a link to a heading (`page.md#heading`) at a heading that exists: pages move
between the README and docs/, and a link left behind is what a reader finds first."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path
from urllib.parse import unquote

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PAGES = [README, *sorted((ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(
    r"(?:^<!-- not run: (?P<reason>.+?) -->\n)?^```python\n(?P<code>.*?)^```", re.M | re.S
)
# Where the examples may be left out, over all pages; a new one that needs leaving out is added
# here on purpose: the SAC + HER example of docs/environments.md needs the `rl` extra, and
# tests/sim/envs/test_env_goal_sb3.py runs it where `make test-slow` installs it; docs/learning.md's
# needs a user's trial and batch.
MOST_NOT_RUN = 2

FENCE = re.compile(r"^(```|~~~).*?^\1[^\n]*$", re.M | re.S)
INLINE_CODE = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"!?\[[^\]\n]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s*\[[^\]\n]+\]:\s*<?(\S+?)>?(?:\s+.*)?$", re.M)
HTML_TARGET = re.compile(r"<(?:img|a)\b[^>]*?\b(?:src|href)=\"([^\"]+)\"", re.I)
HEADING = re.compile(r"^#{1,6}[ \t]+(.+?)[ \t]*#*[ \t]*$", re.M)
EXTERNAL = re.compile(r"^(?:[a-z][a-z0-9+.-]*:|//)", re.I)


def _name(page: Path) -> str:
    return page.relative_to(ROOT).as_posix() if page.is_relative_to(ROOT) else page.name


def _blocks(page: Path) -> list[tuple[int, str, str | None]]:
    text = page.read_text()
    return [
        (text.count("\n", 0, m.start("code")) + 1, m.group("code"), m.group("reason"))
        for m in BLOCK.finditer(text)
    ]


def _prose(text: str) -> str:
    """The page without its code: fenced blocks and inline code (a link there is an example)."""
    return INLINE_CODE.sub("", FENCE.sub("", text))


def _slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link: its text
    text = re.sub(r"<[^>]+>", "", text).replace("`", "").lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    seen: dict[str, int] = {}
    anchors = set()
    for m in HEADING.finditer(FENCE.sub("", page.read_text())):
        slug = _slug(m.group(1))
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        anchors.add(slug if n == 0 else f"{slug}-{n}")
    return anchors


def _targets(page: Path) -> list[str]:
    prose = _prose(page.read_text())
    found = [m.group(1) for p in (LINK, REFERENCE, HTML_TARGET) for m in p.finditer(prose)]
    return [t for t in found if not EXTERNAL.match(t)]


def _broken(page: Path) -> list[str]:
    broken = []
    for target in _targets(page):
        path, _, anchor = target.partition("#")
        file = (page.parent / unquote(path)).resolve() if path else page
        if not file.exists():
            broken.append(f"{target}: no file {file}")
        elif anchor and file.suffix == ".md" and unquote(anchor).lower() not in _anchors(file):
            broken.append(f"{target}: no heading #{anchor} in {_name(file)}")
    return broken


def test_the_pages_have_examples_and_leave_few_out():
    blocks = {page: _blocks(page) for page in PAGES}
    assert any(reason is None for _, _, reason in blocks[README]), "the README's API example"
    every = [block for page_blocks in blocks.values() for block in page_blocks]
    assert len(every) >= 4
    assert sum(reason is not None for _, _, reason in every) <= MOST_NOT_RUN


@pytest.mark.parametrize(
    ("page", "line", "code"),
    [
        pytest.param(page, line, code, id=f"{_name(page)}-line-{line}")
        for page in PAGES
        for line, code, reason in _blocks(page)
        if reason is None
    ],
)
def test_an_example_runs_as_written(page, line, code, tmp_path):
    # A fresh process: nothing imported or defined by a test or another example helps it.
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path
    )
    assert result.returncode == 0, f"{_name(page)} line {line}:\n{result.stderr[-2000:]}"


@pytest.mark.parametrize("page", [pytest.param(p, id=_name(p)) for p in PAGES])
def test_every_relative_link_and_image_resolves(page):
    assert _broken(page) == []


def test_the_link_check_sees_what_it_should(tmp_path):
    # The check itself: a broken file, a broken heading and an image are found; code, external
    # addresses and good links are not reported.
    (tmp_path / "other.md").write_text("# The voice: two tracts\n\n## Same machine, same bits\n")
    (tmp_path / "fig.png").write_bytes(b"")
    page = tmp_path / "page.md"
    page.write_text(
        "# Top\n\n[ok](other.md#same-machine-same-bits) [ok](other.md#the-voice-two-tracts)\n"
        "![ok](fig.png) [ok](#top) [web](https://example.org/x.md) `[code](gone.md)`\n"
        "```\n[code](gone.md)\n```\n"
        "[bad](missing.md) ![bad](missing.png) [bad](other.md#nowhere) [bad](#nowhere)\n"
    )
    broken = _broken(page)
    assert len(broken) == 4, broken
    assert all(any(b.startswith(t) for b in broken) for t in ("missing.md", "missing.png"))
