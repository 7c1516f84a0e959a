"""The files a user of research software looks for beside the code: the licence that
pyproject.toml declares, how to cite the project and the study, and what changed."""

import re
import tomllib
from pathlib import Path

import yaml

REPO = Path(__file__).parent.parent
PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
PACKAGES = ("models", "sim", "learner", "experiments")


def test_the_licence_file_is_the_gpl_3_that_pyproject_declares():
    assert PROJECT["license"] == "GPL-3.0-or-later"
    assert PROJECT["license-files"] == ["LICENSE"]
    text = (REPO / "LICENSE").read_text()
    assert text.split()[:6] == ["GNU", "GENERAL", "PUBLIC", "LICENSE", "Version", "3,"]
    assert "END OF TERMS AND CONDITIONS" in text  # the whole text, not a notice


def test_the_citation_file_cites_this_version_and_the_study():
    cff = yaml.safe_load((REPO / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0"
    assert cff["version"] == PROJECT["version"]
    assert cff["license"] == PROJECT["license"]
    study = cff["preferred-citation"]
    paper = (REPO.parent / "shared" / "reference" / "paper.txt").resolve()
    if paper.exists():  # beside the checkout on the development machine, not in a clone alone
        assert study["title"] in paper.read_text()
    assert study["title"] == "A Unified Model of Speech and Tool Use Early Development"
    assert [a["family-names"] for a in study["authors"]] == ["Forestier", "Oudeyer"]
    assert study["year"] == 2017


def test_the_changelog_starts_with_the_version_being_built():
    text = (REPO / "CHANGELOG.md").read_text()
    (first,) = re.findall(r"^## (\S+)", text, flags=re.M)[:1]
    assert first == PROJECT["version"]


def test_every_package_says_it_is_typed():
    for package in PACKAGES:
        assert (REPO / package / "py.typed").exists(), package
