"""One baseline run into a directory: train the three toys' policies (training.py), then test
them with the project's measure as a trial's final agent is tested, in that trial's room
(experiments/measure/trial_evaluation.py `measured`), and write the evaluation as a trial's:
eval.json, competence.parquet, vocal.parquet, study-tests.parquet.

The directory, in the order written:
- baseline.json: the settings, the trial's config (world, voice), the command, the machine;
- policy-toyK.zip (stable-baselines3's saved model) and training.json, written together after
  each toy's policy: training.json records each policy done (its steps, seconds, SAC's and HER's
  settings, the libraries' versions, the machine, the file's size and SHA-256), so that a run
  stopped resumes at the first toy not done (a toy's training stopped midway starts again);
- the evaluation, eval.json last (storage.write_files: it vouches for the tables).
A directory holding a finished run (eval.json) or another run's settings is refused."""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from experiments.baseline import training
from experiments.baseline.settings import (
    ALGORITHM,
    LEARNER,
    REPLAY_BUFFER,
    BaselineError,
    BaselineSettings,
    summary_config,
    trial_config,
)
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.policy_actor import PolicyActor
from experiments.measure.trial_evaluation import measured
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.baseline_run import file_record, open_baseline_run
from experiments.trial_dir.evaluation import evaluation_files
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked, holds_only_lock
from experiments.trial_dir.reading import EVALUATION_MARK
from sim.config import config_from_dict
from sim.vocal.config import VoiceConfig


def policy_file(toy: int) -> str:
    return f"policy-toy{toy}.zip"


def is_finished(out_dir: str | os.PathLike) -> bool:
    return open_baseline_run(out_dir).is_finished()


def _started(out: Path, settings: BaselineSettings, command: str) -> dict:
    """The run's baseline.json: written for a new run into an empty or new directory, or read
    back and checked against `settings` for one to resume."""
    path = open_baseline_run(out).record_path
    config = trial_config(settings)
    if path.exists():
        try:
            recorded = storage.read_json(path)
            same = recorded["settings"] == settings.record()
        except (storage.CorruptFileError, KeyError, TypeError):
            raise BaselineError(f"{path} is damaged: remove {out} to run it again") from None
        if not same:
            changed = [
                f"{name} {recorded['settings'].get(name)!r} (asked {value!r})"
                for name, value in settings.record().items()
                if recorded["settings"].get(name) != value
            ]
            raise BaselineError(
                f"{out} holds a baseline of other settings ({', '.join(changed)}): "
                "give another --out, or the settings it has"
            )
        return recorded
    if out.exists() and not holds_only_lock(out):
        raise BaselineError(f"{out} is not empty and holds no baseline: give another --out")
    record = {
        "learner": {"name": LEARNER, "algorithm": ALGORITHM, "replay_buffer": REPLAY_BUFFER},
        "settings": settings.record(),
        "toy_steps": {str(t): n for t, n in settings.toy_steps().items()},
        "trial": config,
        "command": command,
        "created_on": provenance.machine_record(),
    }
    storage.write_json(path, record)
    return record


def trained_toys(out: Path) -> dict[str, Any]:
    """training.json's record of the toys done, each checked against its policy file."""
    path = open_baseline_run(out).training_path
    if not path.exists():
        return {}
    try:
        toys = storage.read_json(path)["toys"]
        for toy, entry in toys.items():
            open_baseline_run(out).recorded_bytes(
                policy_file(int(toy)), entry["file"], f"remove {out} to run it again"
            )
    except (KeyError, TypeError, ValueError) as exc:
        raise BaselineError(f"{path} is damaged ({exc}): remove {out} to run it again") from None
    except storage.CorruptFileError as exc:
        raise BaselineError(str(exc).replace("\n", " ")) from None
    return dict(toys)


def run_baseline(
    out_dir: str | os.PathLike,
    settings: BaselineSettings,
    command: str | None = None,
    progress: bool = False,
    notify: Callable[[str], None] | None = None,
) -> dict:
    """Train, or resume, and evaluate one baseline into `out_dir` (the module's docstring);
    eval.json's summary. BaselineError (one line) before any work for a directory that holds a
    finished run, another run or something else, or is being written by another process."""
    out = Path(out_dir)
    if is_finished(out):
        raise BaselineError(
            f"{out} holds a finished baseline ({EVALUATION_MARK}): give another --out, or remove it"
        )
    training.rl_library()  # the extra's absence said before anything is written
    try:
        storage.check_writable(out)
        lock = DirectoryLock(out).acquire()
    except DirectoryLocked as exc:
        raise BaselineError(str(exc)) from None
    except OSError as exc:
        raise BaselineError(f"cannot write into {out}: {storage.reason(exc)}") from None
    try:
        record = _started(out, settings, command or shlex.join(["playroom", "rl-baseline"]))
        _, room = fresh_trial_parts(record["trial"])
        toys = trained_toys(out)
        if toys and notify is not None:
            notify(f"resuming {out}: the policies of toys {', '.join(sorted(toys))} are done")
        steps = settings.toy_steps()
        left = sum(n for t, n in steps.items() if str(t) not in toys)
        shown = progress and left > 0
        with tqdm(total=left, disable=not shown, desc="training", unit="step") as bar:
            for toy, n in steps.items():
                if str(toy) in toys:
                    continue
                env = _env(record, toy, room)
                seed = settings.toy_seed(toy)
                data, entry = training.train_policy(env, n, seed, settings.torch_threads, bar)
                entry["seed"] = seed
                entry["file"] = file_record(data)
                entry["libraries"] = training.library_versions()
                entry["trained_on"] = provenance.short_record(provenance.machine_record())
                toys[str(toy)] = entry
                training_json = storage.json_bytes(storage.finite_or_null({"toys": toys}))
                storage.write_files(
                    out,
                    {
                        policy_file(toy): data,
                        open_baseline_run(out).training_path.name: training_json,
                    },
                )
        summary = evaluate_baseline(out, settings, record, room, toys, progress)
    finally:
        lock.release()
    return summary


def _env(record: dict, toy: int, room: Any) -> training.SameWords:
    """Toy `toy`'s goal environment in the trial's room: its backend, world and words, and the
    voice baseline.json records."""
    voice = config_from_dict(VoiceConfig, record["trial"]["voice"])
    return training.make_env(room.grasp, toy, room.config, voice, room.words)


def evaluate_baseline(
    out: Path,
    settings: BaselineSettings,
    record: dict,
    room: Any,
    toys: dict[str, Any],
    progress: bool,
) -> dict:
    """The policies in `out` tested by the project's measure in the trial's room, as its final
    agent is (trial_evaluation.measured), and the evaluation written beside them."""
    actor = PolicyActor(
        {
            int(t): training.load_policy(
                (out / policy_file(int(t))).read_bytes(), _env(record, int(t), room)
            )
            for t in toys
        }
    )
    # The best distance of any sound made in training to each word, over the three policies
    # (null in training.json: no voice movement, as a trial's before its first).
    best = np.min(
        [
            [np.inf if d is None else d for d in entry["best_word_distance"]]
            for entry in toys.values()
        ],
        axis=0,
    )
    evaluation = EvaluationSettings(n_placements=settings.eval_placements)
    summary, tables = measured(
        actor, actor, room, evaluation, summary_config(settings), best, settings.steps, progress
    )
    summary["learner"] = {"name": LEARNER, "algorithm": ALGORITHM, "replay_buffer": REPLAY_BUFFER}
    storage.write_files(out, evaluation_files(summary, tables, record["trial"]))
    return summary
