"""A run of the deep-RL baseline (`playroom rl-baseline`, experiments/baseline/run.py) as it
lies in its directory: its record (baseline.json: its settings and the trial config its world
comes from), its policies' training record (training.json) and its evaluation, a trial's
(evaluation.py), which marks it finished. Each policy file is recorded in training.json by its
size and SHA-256 (manifest.py's entries), and read back only as recorded.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from experiments.trial_dir import manifest
from experiments.trial_dir.evaluation import Evaluation
from experiments.trial_dir.layout import BASELINE_FILE, TRAINING_FILE

# What marks a folder as a baseline run, as messages say it.
BASELINE_RUN_MARK = BASELINE_FILE


@dataclass(frozen=True)
class BaselineRun:
    """A baseline run's directory."""

    dir: Path

    @property
    def record_path(self) -> Path:
        """baseline.json: the run's settings, written first."""
        return self.dir / BASELINE_FILE

    @property
    def training_path(self) -> Path:
        """training.json: each toy's policy as trained."""
        return self.dir / TRAINING_FILE

    def is_run(self) -> bool:
        """Whether the folder holds a baseline run (its record)."""
        return self.record_path.is_file()

    def evaluation(self) -> Evaluation:
        """Its evaluation, a trial's, in its directory."""
        return Evaluation(self.dir, self.dir)

    def is_finished(self) -> bool:
        """Whether it was evaluated: its last file, eval.json, is there."""
        return self.evaluation().path.is_file()

    def recorded_bytes(self, name: str, record: list, remedy: str) -> bytes:
        """The bytes of the run's file `name` (a policy), checked against `record`, its
        [size, SHA-256] as training.json holds it (`file_record`): storage.CorruptFileError
        (ending with `remedy`) if missing, damaged or replaced; ValueError or TypeError if
        `record` is not one."""
        size, sha256 = record
        recorded = manifest.Manifest(self.dir, {name: manifest.Entry(size, sha256)}, 0)
        return recorded.read_bytes(self.dir / name, remedy)


def file_record(data: bytes) -> list:
    """What training.json records of a file of these `data`: [size, SHA-256]."""
    return manifest.entry_of(data).as_json()


def open_baseline_run(run_dir: str | os.PathLike) -> BaselineRun:
    """A baseline run's directory, for reading or writing; nothing is read yet."""
    return BaselineRun(Path(run_dir))
