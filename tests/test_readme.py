"""Every Python example of the README runs as written, each in a fresh namespace of its own
process, except the few marked `<!-- not run: reason -->` on the line before them (they need a
user's data or a cluster)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
BLOCK = re.compile(
    r"(?:^<!-- not run: (?P<reason>.+?) -->\n)?^```python\n(?P<code>.*?)^```", re.M | re.S
)
# Where the examples may be left out; a new one that needs leaving out is added here on purpose.
MOST_NOT_RUN = 2


def _blocks() -> list[tuple[int, str, str | None]]:
    text = README.read_text()
    return [
        (text.count("\n", 0, m.start("code")) + 1, m.group("code"), m.group("reason"))
        for m in BLOCK.finditer(text)
    ]


def test_the_readme_has_examples_and_leaves_few_out():
    blocks = _blocks()
    assert len(blocks) >= 4
    assert sum(reason is not None for _, _, reason in blocks) <= MOST_NOT_RUN


@pytest.mark.parametrize(
    ("line", "code"),
    [
        pytest.param(line, code, id=f"line-{line}")
        for line, code, reason in _blocks()
        if reason is None
    ],
)
def test_a_readme_example_runs_as_written(line, code, tmp_path):
    # A fresh process: nothing imported or defined by a test or another example helps it.
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path
    )
    assert result.returncode == 0, f"README.md line {line}:\n{result.stderr[-2000:]}"
