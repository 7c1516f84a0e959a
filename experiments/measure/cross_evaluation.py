"""A trial's final agent tested in another world than the one it learned in (issue 40), so that
a difference between two conditions splits into what the agents learned and what the test
world does to the same agents.

A test world is a grasp backend with its own rules as the trial's preset sets them: the trial's
config with `trial.grasp` replaced and every backend switch (a WorldConfig field that declares
the backends it acts on, sim/config.py ACTS_ON: the catch rule, pushing, settling, ...) set to
the preset's value; every other setting (the arm, the DMP, the voice, the learner, the
placements) stays the trial's own. So the "kinematic" world of a study-preset trial is the
comparison's kinematic room (the study's catch rule), its "physical" world the comparison's
physical room (pushing, no settling), whatever rung of a ladder the agent learned in.

The test is the project's own measure and the study's, as `playroom eval` runs them (the same
placements, the random agent acting in the same test world). The study's measure carries its
scene over from test to test, starting, in the trial's own evaluation, from the scene learning
left; that physical state belongs to the world the agent learned in, so in another world the
study's tests start from the test world's start scene (the stick at its start, the toys and
caregiver as its seed places them; docs/protocol.md D24). The vocal table is the trial's
(the best distance to each word reached while learning): no test world changes it.

Written beside the trial, never into its files: `DIR/eval-in-WORLD/` holds eval.json and the
three tables, as one unit (eval.json last, listing the tables with their sizes and SHA-256, as
the trial's own evaluation does), with `test_world` in eval.json saying what was tested.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from experiments import manifest, provenance, storage
from experiments.config_file import config_tested_in
from experiments.file_names import (
    COMPETENCE_FILE,
    CONFIG_FILE,
    EVAL_FILE,
    STUDY_TESTS_FILE,
    VOCAL_FILE,
    cross_evaluation_dir,
)
from experiments.measure.evaluation import (
    EvaluationSettings,
    competence_table,
    summarise_trial,
    vocal_table,
)
from experiments.measure.study_measure import StudyMeasureSettings, study_tests
from experiments.run.lock import DirectoryLock, DirectoryLocked
from experiments.run.trial_checks import load_trial, remove_litter
from experiments.run.trial_files import TrialError, TrialLocked, fresh_trial_parts
from sim.grasping.names import GRASPS

# The test worlds: each grasp backend, with its rules as the trial's preset sets them.
TEST_WORLDS: tuple[str, ...] = GRASPS


def evaluate_in_world(
    trial_dir: str | os.PathLike,
    world: str,
    settings: EvaluationSettings | None = None,
    progress: bool = False,
    notify: Callable[[str], None] | None = None,
) -> dict:
    """Test a trial's final agent in `world` and write `DIR/eval-in-WORLD/` as one unit; its
    summary (eval.json's numbers and `test_world`). TrialError (one line), before any work, for
    a world that is the trial's own (its own evaluation, `playroom eval DIR`, is that test), a
    trial that is not whole (load_trial's checks), or a directory another process writes."""
    settings = settings or EvaluationSettings()
    trial_dir = Path(trial_dir)
    if not (trial_dir / CONFIG_FILE).is_file():
        raise TrialError(f"{trial_dir} holds no trial ({CONFIG_FILE} is missing)")
    try:
        lock = DirectoryLock(trial_dir).acquire()
    except DirectoryLocked as exc:
        raise TrialLocked(str(exc)) from None
    except OSError as exc:
        raise TrialError(f"cannot write into {trial_dir}: {storage.reason(exc)}") from None
    try:
        config, agent, _, meta = load_trial(trial_dir)
        if world not in TEST_WORLDS:
            raise TrialError(f"unknown test world {world!r}: one of {', '.join(TEST_WORLDS)}")
        tested = config_tested_in(config, world)
        if tested == config:
            raise TrialError(
                f"{trial_dir} learned in the {world} world itself: its own evaluation "
                f"(`playroom eval {trial_dir}`) is that test"
            )
        litter = remove_litter(trial_dir)
        if litter and notify is not None:
            notify(f"removed {len(litter)} temporary file(s) of a killed writer")
        _, room = fresh_trial_parts(tested)  # the test world, at its start scene
        start = room.get_state()
        competence = competence_table(agent, room, settings, progress=progress)
        vocal = vocal_table(meta["best_word_distance"], room.words.names)
        summary = summarise_trial(config, competence, vocal)
        summary["evaluated_at_iteration"] = int(meta["iteration"])
        summary["n_placements"] = settings.n_placements
        summary["evaluated_on"] = provenance.short_record(provenance.machine_record())
        switches = {k: v for k, v in tested["world"].items() if v != config["world"].get(k)}
        summary["test_world"] = {"name": world, "grasp": world, "world_changed": switches}
        room.set_state(start)
        study = study_tests(agent, room, StudyMeasureSettings(settings.n_placements))
        files = {
            COMPETENCE_FILE: storage.table_bytes(competence),
            VOCAL_FILE: storage.table_bytes(vocal),
            STUDY_TESTS_FILE: storage.table_bytes(study),
        }
        summary[manifest.EVAL_FILES_KEY] = manifest.evaluation_files(files)
        files[EVAL_FILE] = storage.json_bytes(storage.finite_or_null(summary))
        storage.write_files(cross_evaluation_dir(trial_dir, world), files)
    finally:
        lock.release()
    return summary
