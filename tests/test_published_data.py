"""The make targets whose pages docs/ quotes copy each page's per-trial data into docs/data/
(checked with `make -n`: the recipes printed, nothing run), so that a reader of docs/ holds the
trials behind every number quoted and can test it again."""

import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).parent.parent
# Target -> its pages' folders under OUT, the per-trial file each writes, its name in docs/data/.
PUBLISHED = {
    "comparison-diva": [
        ("comparison-diva-report", "comparison-trials.csv", "comparison-diva-trials.csv")
    ],
    "contact-ablations": [
        ("contact-ablations", "ablations-trials.csv", "contact-ablations-trials.csv")
    ],
    "contact-ladder": [("contact-ladder", "ladder-trials.csv", "contact-ladder-trials.csv")],
    "contact-unbundled": [
        ("contact-unbundled", "ladder-trials.csv", "contact-unbundled-trials.csv")
    ],
    "held-pose-returns": [
        ("held-pose-returns", "ladder-trials.csv", "held-pose-returns-trials.csv")
    ],
    "contact-factorial": [
        (
            f"contact-factorial-{page}",
            "factorial-trials.csv",
            f"contact-factorial-{page}-trials.csv",
        )
        for page in ("held-pose-pushing", "catch-servo", "catch-distance")
    ],
    "ablations": [
        ("ablations-from-study", "ablations-trials.csv", "ablations-from-study-trials.csv"),
        ("ablations-from-project", "ablations-trials.csv", "ablations-from-project-trials.csv"),
    ],
}


@pytest.mark.parametrize("target", PUBLISHED)
def test_a_page_docs_quotes_has_its_per_trial_data_copied_into_docs_data(target, tmp_path):
    printed = subprocess.run(
        ["make", "-n", target, f"OUT={tmp_path}"],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    commands = " ".join(printed.replace("\\\n", " ").split())
    for folder, written, published in PUBLISHED[target]:
        assert f"cp {tmp_path}/{folder}/{written} docs/data/{published}" in commands
