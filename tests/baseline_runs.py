"""Baseline runs written without an RL library, for the tests that read them: the evaluation a
run of `playroom rl-baseline` writes (trial_evaluation.measured), of a policy that rests the
arm, with the run's baseline.json (its settings and its trial's world)."""

from __future__ import annotations

import numpy as np

from experiments.baseline.settings import BaselineSettings, run_name, summary_config, trial_config
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.policy_actor import PolicyActor
from experiments.measure.trial_evaluation import measured
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir import storage
from experiments.trial_dir.evaluation import evaluation_files
from experiments.trial_dir.layout import BASELINE_FILE


class RestingPolicy:
    def predict(self, observation, deterministic=False):
        action = np.zeros(50, dtype=np.float32)
        action[0] = -1.0  # the arm, at rest
        return action, None


def write_run(root, seed: int, steps: int = 30, placements: int = 1) -> None:
    """A run of `steps` movements evaluated on `placements` per ring, its policy at rest."""
    settings = BaselineSettings(steps=steps, seed=seed, eval_placements=placements)
    _, room = fresh_trial_parts(trial_config(settings))
    actor = PolicyActor({t: RestingPolicy() for t in (1, 2, 3)})
    evaluation = EvaluationSettings(placements)
    config = summary_config(settings)
    summary, tables = measured(actor, actor, room, evaluation, config, np.full(6, np.inf), steps)
    out = root / run_name(settings)
    trial = trial_config(settings)
    record = storage.json_bytes({"settings": settings.record(), "trial": trial})
    storage.write_files(out, {BASELINE_FILE: record, **evaluation_files(summary, tables, trial)})
