"""A trial's opening reads from top to bottom (experiments/run/trial.py, through the trial
directory's writing face, experiments/trial_dir/writing.py, to its opening): the trial types its
settings, builds its parts, then only asks the writing face, which calls each stage in one
stretch, in order, and no module of experiments is called back by one it called, for a new
trial and for a resume. Followed with a profiler over the calls between modules, from the
trial's creation to its first iteration."""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import pytest

import experiments
from experiments.run.settings import TrialSettings
from experiments.run.trial import Trial, run_trial

ROOT = Path(experiments.__file__).resolve().parent
# What the trial calls, in order: its settings typed, its parts built, then the directory's
# writing face only (the opening, who computes, what the backend declares).
CALLED = ["run.trial_config", "run.trial_parts", "trial_dir.writing"]
# The writing face's stages, in the order it calls them: the opening, who computes, what the
# backend declares, then the records written or regenerated (one call per record).
STAGES = [
    "trial_dir.opening",
    "trial_dir.provenance_file",
    "trial_dir.backend_record",
    "trial_dir.records",
]

# What every step of the opening reads and writes through: the trial directory's files.
FILE_LAYERS = {f"trial_dir.{m}" for m in ("storage", "layout", "config_file", "manifest")}


def _module(filename: str) -> str | None:
    try:
        return ".".join(Path(filename).resolve().relative_to(ROOT).with_suffix("").parts)
    except ValueError:
        return None


def _calls(make_trial) -> tuple[dict[str, list[str]], Counter]:
    """The modules of experiments that each module enters (is on the stack when it is entered
    from outside), in order, and every call between two modules of experiments
    (caller, callee)."""
    stack: list[str | None] = []
    edges: Counter = Counter()
    entered: dict[str, list[str]] = {}
    names: dict[str, str | None] = {}

    def profile(frame, event, arg):
        if event == "call":
            filename = frame.f_code.co_filename
            module = names.setdefault(filename, _module(filename))
            caller = next((m for m in reversed(stack) if m), None)
            if module and caller and caller != module:
                edges[caller, module] += 1
                if module not in stack:
                    entered.setdefault(caller, []).append(module)
            stack.append(module)
        elif event == "return" and stack:
            stack.pop()

    sys.setprofile(profile)
    try:
        trial = make_trial()
    finally:
        sys.setprofile(None)
    trial.close()
    return entered, edges


def _cycle(edges: Counter) -> list[str] | None:
    """A module reached again from itself through the calls, or None."""
    graph: dict[str, set[str]] = {}
    for caller, callee in edges:
        graph.setdefault(caller, set()).add(callee)

    def walk(node: str, path: list[str]) -> list[str] | None:
        for nxt in sorted(graph.get(node, ())):
            if nxt in path:
                return [*path[path.index(nxt) :], nxt]
            found = walk(nxt, [*path, nxt])
            if found:
                return found
        return None

    return next((c for n in sorted(graph) if (c := walk(n, [n]))), None)


@pytest.mark.parametrize("resume", [False, True])
def test_a_trial_opens_top_to_bottom(tmp_path, resume):
    settings = TrialSettings(iterations=20, seed=1, checkpoint_every=10)
    out = tmp_path / "trial"
    if resume:  # a trial with checkpoints and logs, extended
        run_trial(out, settings, progress=False)
        settings = TrialSettings(iterations=40, seed=1, checkpoint_every=10)
    entered, edges = _calls(lambda: Trial(out, settings, resume=resume))
    assert list(dict.fromkeys(entered["run.trial"])) == CALLED
    stages = entered["trial_dir.writing"]
    # Each stage in one stretch, in order: none entered again once a later one was.
    assert [m for i, m in enumerate(stages) if i == 0 or stages[i - 1] != m] == STAGES
    assert _cycle(edges) is None
    # The opening enters each of its own steps once (the disk estimate, the lock, then for a
    # resume the checks of what lies in the directory; a new trial's litter is removed by the
    # file layer that names temporary files), whatever file layers each reads through.
    steps = [m for m in entered["trial_dir.opening"] if m not in FILE_LAYERS]
    expected = ["run.estimate", "trial_dir.lock"] + (["trial_dir.resume"] if resume else [])
    assert steps[: len(expected)] == expected
    assert len(steps) == len(set(steps))
