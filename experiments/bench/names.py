"""The sections of `playroom bench`, by name, without what measures them: the command line
lists them in its help without loading a simulator (experiments/bench/sections.py measures)."""

from __future__ import annotations

SECTION_NAMES = ("trial", "learner", "world", "tracking", "voice", "render", "emulated")
