"""What a reader who has not read the paper needs on every report and comparison page, said
before the first table: the experiment, the tests, the rings in metres and what normalised
competence means (experiments/report/intro.py, macros.html.j2 `intro`)."""

from __future__ import annotations

import html
import re


def check_explained(page: str, n_trials_warned: bool) -> None:
    """The opening paragraph comes before the first table and says what it must; the
    few-trials warning is shown exactly when `n_trials_warned`."""
    before = html.unescape(re.sub(r"<[^>]+>", "", page[: page.index("<table>")]))
    before = " ".join(before.split())
    for needed in (
        "goal babbling",
        "Forestier & Oudeyer (2017)",
        "bring it to the arm's base",
        "ring 1: 0–0.5 m (within the hand's reach)",
        "ring 2: 0.5–0.75 m (beyond the hand, within the stick's reach)",
        "ring 3: 0.75–1 m (beyond both: only the caregiver can bring it)",
        "0% = as good as a random command, 100% = perfect",
        "as the study computed it",
    ):
        assert needed in before, needed
    assert ("Few trials:" in before) == n_trials_warned
