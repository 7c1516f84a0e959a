"""Competence and strategies as the study computed them (docs/protocol.md §10, D20-D23), its
quirks reproduced, for comparison with the paper beside the project's own measure.

How the study's code measured (its scripts/run.py and analysis notebooks):
- tests: per ring, 100 placements of all 3 toys in the ring, one test per toy, in one scene
  that carries over: the stick stays where the last test left it, moved toys stay moved, the
  caregiver is redrawn after every movement and the room's own counter re-places every toy
  every 20 movements; the goal is the toy's current position moved straight to the base;
- strategy: the arm or the voice model of the toy, whichever has the nearer experience (a tie
  goes to the voice); when the voice model had data, the arm model's inverse was queried with
  the voice model's context values (toy, caregiver) in place of its own (stick, toy);
- a test used the tool when the stick's x moved between the first and the last sample (any
  difference at all; the rows keep that difference, `stick_dx`, so that a report can also
  count the tool uses that moved the stick less than a minimum motion);
- placements: drawn anew in every run (the study used the global random state), so that
  pooled over runs the tests cover the whole disk; here from the trial's own seed;
- random reference (notebook motor_babbling): per ring, 10000 placements, one random command
  (arm or voice, 1/2 each) per toy as goal, so 30000 commands, whose error was read on toy 1's
  trajectory whatever the goal toy; here its commands are played in chunks of 1500, each from
  a fresh room with its own seed, on every core (reference_pool.py): the scene carries over
  within a chunk, not across chunks as in the notebook's one stream;
- map (notebook analysis_competence): errors pooled over runs on a 100 x 100 grid over
  [-1, 1]^2 by the toy's position (pixel i holds x in [i/50 - 1, (i+1)/50 - 1)); the reference
  of a pixel at pixel-distance d from pixel (50, 50) is the unweighted mean of the per-pixel
  reference means of every pixel at a distance in (d - 1, d + 1) that holds one; per pixel
  max(0, 1 - agent / random). How the paper's "46%" averaged the pixels is not in the study's
  notebooks: here, the mean over every pixel that holds a test (with placements drawn anew
  per run, about the mean over the disk);
- strategies (Fig. 4): each pixel's shares of hand, tool and vocal tests, averaged over the
  pixels of each radial bin int(pixel-distance) < 50 (a pixel without a test counts 0), then
  renormalised in sequence as the notebook did (the tool share divided by a sum that already
  holds the renormalised hand share). The curve is plotted at x = bin / 49; "distance 1" is its
  last bin, the regions "centre" and "between the limits" its bins left of 0.6 and between
  0.6 and 0.85 on that axis, averaged (the paper read them off the curve).
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

import models
import sim
from experiments.analysis.study_summary import RANDOM_COMMANDS_PER_RING, study_summary
from experiments.measure import reference_pool
from experiments.measure.actors import Actor, Choice
from experiments.measure.evaluation import goal_trajectory, movement_contacts, strategy_of
from experiments.measure.reference_pool import CHUNK_COMMANDS, play_references, ring_placement
from learner.agent import Agent
from models.layout import MOTOR_DIMS, TOYS, block_slice, context_indices
from sim import Playroom


@dataclass(frozen=True)
class StudyMeasureSettings:
    n_placements: int = 100
    random_commands_per_ring: int = RANDOM_COMMANDS_PER_RING
    seed: int = 20170001  # the trial's seed joins it: placements differ from run to run


def _arm_context_of_the_study(context: np.ndarray, toy: str) -> np.ndarray:
    """A context whose arm-model slots (stick, toy) hold the voice model's values (toy,
    caregiver): what the study's arm inverse was queried with when the voice had data."""
    swapped = context.copy()
    swapped[list(context_indices("stick"))] = context[list(context_indices(toy))]
    swapped[list(context_indices(toy))] = context[list(context_indices("caregiver"))]
    return swapped


class StudyLearnerActor:
    """The Model Babbling agent as the study's code asked it (the module's docstring): the
    model with the nearer experience, a tie to the voice; the arm model asked with the voice
    model's context values when the voice model had data; the arm at rest when neither had."""

    def __init__(self, agent: Agent) -> None:
        self.agent = agent

    def choose(self, toy: int, context: np.ndarray, goal: np.ndarray) -> Choice:
        agent, name = self.agent, TOYS[toy - 1]
        arm, voice = agent.toy_models(toy)
        d_arm = agent.nearest_distance(arm, context, goal)
        d_voice = agent.nearest_distance(voice, context, goal)
        if d_arm < d_voice:
            asked = context if np.isinf(d_voice) else _arm_context_of_the_study(context, name)
            return Choice("arm", agent.exploit(arm, asked, goal), d_arm, d_voice)
        if np.isfinite(d_voice):
            return Choice("voice", agent.exploit(voice, context, goal), d_arm, d_voice)
        return Choice("arm", np.zeros(MOTOR_DIMS["arm"]), d_arm, d_voice, untrained=True)


def study_tests(agent: Agent, room: Playroom, settings: StudyMeasureSettings) -> pd.DataFrame:
    """`study_tests_of` the Model Babbling agent as the study asked it (`StudyLearnerActor`)."""
    return study_tests_of(StudyLearnerActor(agent), room, settings)


def study_tests_of(actor: Actor, room: Playroom, settings: StudyMeasureSettings) -> pd.DataFrame:
    """One row per test: ring, toy, x, y (the toy's position), strategy, stick_dx (the stick's
    x at the last sample minus at the first, m), error, stick_contact and goal_moved_by
    (`movement_contacts`). The scene carries over from test to test; the actor only chooses
    (actors.py)."""
    rng = np.random.default_rng([settings.seed, room.seed])
    rows = []
    for ring_number, ring in enumerate(room.config.toy_rings, start=1):
        for _ in range(settings.n_placements):
            room.arrange(toys=ring_placement(ring, rng))
            for t, toy in enumerate(TOYS, start=1):
                context = room.context()
                position = context[list(context_indices(toy))]
                goal = goal_trajectory(position)
                choice = actor.choose(t, context, goal)
                space, m = choice.motor_space, choice.command
                feedback = room.act(space, m)
                s = feedback.s
                stick_contact, goal_moved_by = movement_contacts(feedback.events, toy)
                stick_x = s[block_slice("stick")][:5]
                rows.append(
                    {
                        "ring": ring_number,
                        "toy": t,
                        "x": position[0],
                        "y": position[1],
                        "strategy": strategy_of(space, bool(stick_x[0] != stick_x[-1])),
                        # m, what the rule compared: reports count the tool uses it made of
                        # sub-millimetre motions (experiments/analysis/stats.py, tool_motion).
                        "stick_dx": float(stick_x[-1] - stick_x[0]),
                        "error": float(np.linalg.norm(s[block_slice(toy)] - goal)),
                        "stick_contact": stick_contact,
                        "goal_moved_by": goal_moved_by,
                    }
                )
    return pd.DataFrame(rows)


def random_reference(
    configs: dict[str, dict],
    settings: StudyMeasureSettings,
    workers: int | None = None,
    progress: bool | None = None,
    chunk_commands: int = CHUNK_COMMANDS,
) -> dict[str, pd.DataFrame]:
    """The random reference of each group of `configs` (group -> a trial's config): one row per
    random command, x, y of the goal toy and the error read on toy 1, ring by ring. Played in
    chunks of `chunk_commands`, each from a fresh room with its own seed, on `workers`
    processes (default: the cores), the same rows whatever their number
    (experiments/measure/reference_pool.py: the scene carries over within a chunk only). A
    group whose config makes no room is left out. progress: one bar on stderr (None: only on a
    terminal)."""
    return play_references(
        configs,
        settings.seed + 1,
        settings.random_commands_per_ring,
        workers=workers,
        progress=progress,
        chunk_commands=chunk_commands,
    )


# Where played random references are kept between reports: this variable if set (tests,
# clusters whose home is small or shared), else the user's cache directory.
CACHE_ENV = "PLAYROOM_CACHE_DIR"


def reference_cache_dir() -> Path:
    """Where `study_numbers` keeps the random references it played: $PLAYROOM_CACHE_DIR, else
    the user's cache directory (platformdirs: ~/.cache/playroom on Linux). Never a batch
    directory: a report only reads its batches, which may be read-only or shared."""
    override = os.environ.get(CACHE_ENV)
    if override:
        return Path(override)
    import platformdirs

    return Path(platformdirs.user_cache_dir("playroom"))


@functools.cache
def code_digest() -> str:
    """A digest of what plays a reference (this module and the pool's, the room's code, model
    and voice data): a reference kept by another version of the project is not read back as
    this one's."""
    digest = hashlib.sha256(Path(__file__).read_bytes())
    assert reference_pool.__file__ is not None
    digest.update(Path(reference_pool.__file__).read_bytes())
    for package in (sim, models):
        assert package.__file__ is not None  # regular packages, not namespace ones
        folder = Path(package.__file__).parent
        files = (p for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
        for path in sorted(files):
            digest.update(str(path.relative_to(folder)).encode() + path.read_bytes())
    return digest.hexdigest()


def read_kept(path: Path) -> pd.DataFrame | None:
    from experiments.trial_dir import storage

    try:
        return storage.read_table(path) if path.exists() else None
    except storage.CorruptFileError:  # damaged (a cache is not kept with care): played again
        return None


def keep(path: Path, reference: pd.DataFrame) -> None:
    """Keep a played reference, if the cache can take it: a report never fails for its cache
    (a full or read-only cache directory only means playing the reference again next time)."""
    from experiments.trial_dir import storage

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        storage.write_table(path, reference)
    except OSError:
        pass


def study_numbers(
    results,
    commands_per_ring: int = RANDOM_COMMANDS_PER_RING,
    cache_dir: Path | None = None,
    progress: bool | None = None,
    workers: int | None = None,
    chunk_commands: int = CHUNK_COMMANDS,
    beside: Callable[..., dict] | None = None,
) -> dict[str, dict]:
    """`study_summary` of each group of a batch (`experiments.analysis.results.BatchResults`) whose
    trials hold the study's tests: their tests pooled over trials (the study averaged errors
    per pixel over its runs), against a random reference played in fresh rooms of the group's
    settings (`random_reference`, every group not kept yet on one pool of `workers`
    processes, default: the cores). The reference depends on the settings and the code alone:
    it is kept in `cache_dir` (default: `reference_cache_dir()`) as
    `study-reference-<digest>.parquet` and read back by later reports, comparisons and
    ablations of any batch of those settings. progress: a bar of the commands played (None:
    only on a terminal). `beside`: what else to measure of each group against its reference
    (config, trials, tests, reference, cache), kept as its numbers' `untrained`: the reports
    give experiments/measure/untrained.py's `untrained_numbers` (for_reports.py)."""
    cache = Path(cache_dir) if cache_dir is not None else reference_cache_dir()
    tests_of, paths, references, to_play = {}, {}, {}, {}
    for group, config in results.configs.items():
        tests = results.study_tests[results.study_tests["group"] == group]
        if tests.empty:
            continue
        tests_of[group] = tests
        # The trial's seed is not the reference's: one reference serves every trial.
        config = {**config, "trial": {**config["trial"], "seed": 0}}
        key = json.dumps(
            {
                "config": config,
                "commands": commands_per_ring,
                "chunk": chunk_commands,
                "code": code_digest(),
            },
            sort_keys=True,
        )
        digest = hashlib.sha256(key.encode()).hexdigest()[:16]
        paths[group] = cache / f"study-reference-{digest}.parquet"
        kept = read_kept(paths[group])
        if kept is None:
            to_play[group] = config
        else:
            references[group] = kept
    if to_play:  # every group not kept yet on one pool: two groups share the cores
        settings = StudyMeasureSettings(random_commands_per_ring=commands_per_ring)
        played = random_reference(to_play, settings, workers, progress, chunk_commands)
        for group, reference in played.items():
            keep(paths[group], reference)
        references.update(played)
    numbers = {}
    for group, tests in tests_of.items():
        if group not in references:  # settings no room can be built from: "not measured"
            continue
        numbers[group] = study_summary(tests, references[group])
        numbers[group]["reference_commands_per_ring"] = commands_per_ring
        if beside is not None:
            trials = results.trials[results.trials["group"] == group]
            numbers[group]["untrained"] = beside(
                results.configs[group], trials, tests, references[group], cache
            )
    return numbers
