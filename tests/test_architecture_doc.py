"""docs/architecture.md names every module of the packages, and only modules that exist: a
newcomer finds each file there, one line on what it holds."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"
PACKAGES = ("models", "sim", "learner", "experiments")
# "- **sim/grasping/**: ..." opens a package's list; "  - `a.py`, `b.py`: ..." names modules.
_PACKAGE_LINE = re.compile(r"^- \*\*([\w/]+/)\*\*")
_ENTRY_LINE = re.compile(r"^\s+- (`[^:]*`)\s*:")
_MODULE = re.compile(r"`([\w/]+\.py)`")


def documented_modules(text: str) -> set[str]:
    """The module paths the page's "Every module" lists name, package prefix included."""
    found: set[str] = set()
    package: str | None = None
    for line in text.splitlines():
        if line.startswith("## "):
            package = None
        opened = _PACKAGE_LINE.match(line)
        if opened:
            package = opened.group(1)
            continue
        entry = _ENTRY_LINE.match(line)
        if package and entry:
            found.update(package + name for name in _MODULE.findall(entry.group(1)))
    return found


def package_modules() -> set[str]:
    """Every module of the four packages, as paths from the repository's root."""
    return {
        path.relative_to(ROOT).as_posix()
        for package in PACKAGES
        for path in (ROOT / package).rglob("*.py")
        if path.name != "__init__.py"
    }


def test_every_module_is_on_the_architecture_page():
    missing = sorted(package_modules() - documented_modules(DOC.read_text()))
    assert not missing, f"docs/architecture.md does not name: {missing}"


def test_the_architecture_page_names_no_module_that_is_gone():
    stale = sorted(documented_modules(DOC.read_text()) - package_modules())
    assert not stale, f"docs/architecture.md names modules that do not exist: {stale}"


def test_the_parser_reads_packages_and_several_modules_a_line():
    page = (
        "- **sim/grasping/**: backends\n"
        "  - `base.py`: the interface\n"
        "  - `a.py`, `b.py`: two at once (`not_this.py` after the colon)\n"
        "## Next\n"
        "  - `outside.py`: no package\n"
    )
    assert documented_modules(page) == {
        "sim/grasping/base.py",
        "sim/grasping/a.py",
        "sim/grasping/b.py",
    }
