"""Hand-made batch tables (`BatchResults`) whose per-trial values are chosen, for the tests of
statistics over trials (tests/report/test_differences.py): one group per call, one trial per
seed, only the tables and columns a test gives (every other measure is then not recorded)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults

# The study's limits and recognition distance (no config is read for hand-made tables).
GEOMETRY = Geometry(hand_limit=0.5, stick_limit=0.75, threshold=0.4, bootstrap=0)


def trial_name(group: str, seed: int) -> str:
    return f"{group}-seed{seed:04d}"


def batch(
    group: str,
    seeds: Sequence[int],
    *,
    competence: Sequence[float] | None = None,
    tool_tests: Sequence[tuple[int, int]] | None = None,
    pushed: Sequence[int] | None = None,
    words: Sequence[tuple[Sequence[float], Sequence[float]]] | None = None,
    pushes: bool = True,
    grasp: str | None = None,
) -> BatchResults:
    """One group's trials, seed by seed: `competence` (competence_all), `tool_tests` (tool and
    hand tests near the centre, the study's rule), `pushed` (how many of the tool tests only
    pushed the stick), `words` (best distances of the names, then of the distractors),
    whether its backend `pushes` (backend.json), and its `grasp` backend (default: the group's
    name)."""
    trials = pd.DataFrame(
        {
            "trial": [trial_name(group, s) for s in seeds],
            "group": group,
            "seed": list(seeds),
            "grasp": grasp or group,
            "pushes": pushes,
            "closed_form": not pushes,
        }
    )
    if competence is not None:
        trials["competence_all"] = list(competence)
    tests = []
    for k, seed in enumerate(seeds):
        if tool_tests is None:
            break
        tools, hands = tool_tests[k]
        only_pushed = pushed[k] if pushed is not None else 0
        for i in range(tools + hands):
            tests.append(
                {
                    "trial": trial_name(group, seed),
                    "group": group,
                    "seed": seed,
                    "ring": 1,
                    "distance": 0.2,
                    "strategy": "tool" if i < tools else "hand",
                    "stick_grasped": not (i < only_pushed),
                }
            )
    vocal = []
    for k, seed in enumerate(seeds):
        if words is None:
            break
        names, distractors = words[k]
        for is_name, distances in ((True, names), (False, distractors)):
            for d in distances:
                vocal.append(
                    {
                        "trial": trial_name(group, seed),
                        "group": group,
                        "seed": seed,
                        "is_name": is_name,
                        "best_distance": d,
                    }
                )
    columns = ["trial", "group", "seed"]
    return BatchResults(
        batch_dir=Path(group),
        trials=trials,
        competence=pd.DataFrame(tests, columns=None if tests else columns),
        vocal=pd.DataFrame(vocal, columns=None if vocal else columns),
        curves=pd.DataFrame(columns=columns),
        configs={group: {}},
    )
