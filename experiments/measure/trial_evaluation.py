"""A trial evaluated after learning: the project's measure (experiments/measure/evaluation.py)
and the study's tests (experiments/measure/study_measure.py), from the trial's final state,
written into the trial directory as one unit (eval.json last).

The final agent can also be tested in an eval world other than its own (experiments/
eval_worlds.py): the same evaluation, in a room of that world built as the trial's own is
(`fresh_trial_parts`), written beside the trial's files in `eval-in-NAME/`, whose eval.json
records the world (`eval_world`). The study's measure there starts from that room's start
scene, not from the scene learning left, which is a state of the trial's own world
(docs/protocol.md D26)."""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np

from experiments.measure.actors import Actor, LearnerActor
from experiments.measure.evaluation import (
    EvaluationSettings,
    competence_of,
    summarise_trial,
    vocal_table,
)
from experiments.measure.study_measure import (
    StudyLearnerActor,
    StudyMeasureSettings,
    study_tests_of,
)
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.eval_worlds import OWN, EvalWorldError, own_world, world_record
from experiments.trial_dir.evaluation import Evaluation
from experiments.trial_dir.reading import SCENES_KEY, TrialReading
from experiments.trial_dir.writing import open_for_evaluation
from sim import Playroom


def evaluate_trial(
    trial_dir: str | os.PathLike,
    settings: EvaluationSettings | None = None,
    progress: bool = False,
    notify: Callable[[str], None] | None = None,
    world: str = OWN,
) -> dict:
    """Evaluate a trial's final state and write eval.json and the tables beside it, as one
    unit: a write that fails (disk full) leaves the trial's evaluation files as they were.
    TrialError, before any work, for a directory that cannot be written (read-only), or that
    another process writes into (named). The temporary files of killed writers are removed
    first; `notify` is told their names.

    `world`: an eval world's name (experiments/trial_dir/eval_worlds.py) tests the final agent
    there and writes into `eval-in-<world>/` instead, the trial's own files untouched; an eval
    world equal to the trial's own is its own evaluation (`notify` is told so)."""
    settings = settings or EvaluationSettings()
    # Evaluation writes into the trial directory: one writer at a time, as for the trial.
    writer = open_for_evaluation(trial_dir)
    try:
        config, agent, room, meta = writer.trial.restored(fresh_trial_parts)
        litter = writer.remove_litter()
        if litter and notify is not None:
            notify(
                f"removed {len(litter)} temporary file(s) of a killed writer: {', '.join(litter)}"
            )
        evaluation, room = _where_tested(writer.trial, config, room, world, notify)
        writer.check_writable(evaluation)  # before minutes of tests whose results could not be kept
        summary, tables = measured(
            LearnerActor(agent),
            StudyLearnerActor(agent),
            room,
            settings,
            config,
            meta["best_word_distance"],
            int(meta["iteration"]),
            progress,
        )
        if evaluation.folder != writer.trial.dir:
            summary["eval_world"] = world_record(config, world)
        writer.write(evaluation, summary, tables, config)
    finally:
        writer.close()
    return summary


def _where_tested(
    trial: TrialReading,
    config: dict,
    room: Playroom,
    world: str,
    notify: Callable[[str], None] | None,
) -> tuple[Evaluation, Playroom]:
    """(the evaluation written, the room it tests in): the trial's own, and the room restored
    with the trial, for its own world, else its evaluation in `eval-in-<world>/` and a fresh
    room of that world, built from the trial's config as the trial's own room is (its seed,
    voice and every setting but the backend and its switches)."""
    try:
        own = world == OWN or own_world(config, world)
    except EvalWorldError as exc:
        raise TrialError(f"{trial.dir}: {exc}") from None
    if own:
        if world != OWN and notify is not None:
            notify(
                f"{trial.dir} learned in the {world} world: its evaluation there is its own, "
                "eval.json in the trial directory (one evaluation per world)"
            )
        return trial.evaluation(), room
    tested = world_record(config, world)
    settings = {**config["trial"], "grasp": tested["grasp"]}
    _, tested_room = fresh_trial_parts({**config, "trial": settings, "world": tested["world"]})
    return trial.evaluation_elsewhere(world), tested_room


def measured(
    actor: Actor,
    study_actor: Actor,
    room: Playroom,
    settings: EvaluationSettings,
    config: dict,
    best_word_distance: np.ndarray,
    evaluated_at: int,
    progress: bool = False,
) -> tuple[dict, dict[str, bytes]]:
    """(eval.json's numbers, the tables' bytes by kind: evaluation.TABLES) of an actor tested in
    `room` as a trial's final agent is: the project's measure (`competence_of`, `actor`), the vocal
    table of `best_word_distance` (the best distance of the learner's own sounds to each word, in
    the order of the voice's words) and the study's tests (`study_tests_of`, `study_actor`), which
    start from the room's scene as it is now. `config`: the trial's (or a config of its form: its
    "trial" section's grasp, seed, babbling and iterations are summarised). The same for every
    learner: only the actors differ."""
    # The study's measure starts from it too: the scene learning left, or in another world,
    # that world's start scene.
    final_state = room.get_state()
    competence = competence_of(actor, room, settings, progress=progress)
    vocal = vocal_table(best_word_distance, room.words.names)
    summary = summarise_trial(config, competence, vocal)
    summary["evaluated_at_iteration"] = int(evaluated_at)
    summary["n_placements"] = settings.n_placements
    if settings.scenes_clear_of_stick:
        summary[SCENES_KEY] = True
    # The evaluation is computed too: its numbers carry the machine's bits as well.
    summary["evaluated_on"] = provenance.short_record(provenance.machine_record())
    # The study measured in the scene its tests start from (above), carried over from test to
    # test.
    room.set_state(final_state)
    study = study_tests_of(study_actor, room, StudyMeasureSettings(settings.n_placements))
    tables = {
        "competence": storage.table_bytes(competence),
        "vocal": storage.table_bytes(vocal),
        "study_tests": storage.table_bytes(study),
    }
    return summary, tables
