"""A trial's evaluation as it lies in one folder: the trial directory for its own world,
`eval-in-WORLD/` for another (eval_worlds.py); eval.json, checked against itself and the trial
(eval_record.py), and the tables it lists, each checked against the size and SHA-256 eval.json
records of it before it is read. Also what an evaluation writes: its files, eval.json last
(`evaluation_files`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from experiments.trial_dir import eval_record, manifest, storage
from experiments.trial_dir.eval_worlds import SWITCHES, world_record
from experiments.trial_dir.layout import (
    COMPETENCE_FILE,
    EVAL_FILE,
    EVALUATION_TABLES,
    STUDY_TESTS_FILE,
    VOCAL_FILE,
    eval_world_dir,
)

# The tables of an evaluation, by what they hold.
TABLES = {"competence": COMPETENCE_FILE, "vocal": VOCAL_FILE, "study_tests": STUDY_TESTS_FILE}


class EvalWorldMismatch(storage.CorruptFileError):
    """An evaluation folder of a trial made for another eval world, or as another declaration
    of it than the one in experiments/trial_dir/eval_worlds.py now (one line)."""


@dataclass(frozen=True)
class Evaluation:
    """A trial's evaluation in `folder` (the trial directory `trial_dir`, or one of its
    eval-in-WORLD/ folders)."""

    trial_dir: Path
    folder: Path

    @property
    def path(self) -> Path:
        """Its eval.json, which vouches for the rest (as messages name it)."""
        return self.folder / EVAL_FILE

    def exists(self) -> bool:
        return self.path.exists()

    def remedy(self) -> str:
        """What a user does about it damaged, missing or another's: evaluate again."""
        return eval_record.evaluation_remedy(self.trial_dir, self.folder)

    def summary(self, config: dict, remedy: str | None = None, warn: bool = True) -> dict:
        """eval.json's numbers, checked against itself and the trial of `config`
        (eval_record.read_evaluation; manifest.DamagedFileError, one line ending in `remedy`,
        by default `self.remedy()`)."""
        remedy = self.remedy() if remedy is None else remedy
        return eval_record.read_evaluation(self.folder, config, remedy, warn)

    def table_path(self, kind: str) -> Path:
        """Where the table of `kind` (a key of TABLES) lies, as messages name it."""
        return self.folder / TABLES[kind]

    def table(self, kind: str, summary: dict) -> pd.DataFrame | None:
        """The table of `kind` (a key of TABLES), checked against eval.json (`summary`) before
        it is read; None for one an evaluation from before it existed lacks.
        storage.CorruptFileError (manifest.DamagedFileError) for one missing, damaged or of
        another evaluation."""
        path = self.table_path(kind)
        data = manifest.read_evaluation_file(self.folder, path.name, summary)
        return None if data is None else storage.read_table(path, data=data)

    def required_table(self, kind: str, summary: dict) -> pd.DataFrame:
        """`table`, for a table every evaluation wrote: one missing is a
        storage.CorruptFileError whichever evaluation it is."""
        path = self.table_path(kind)
        data = manifest.read_evaluation_file(self.folder, path.name, summary)
        return storage.read_table(path, data=data)

    def check_tables(self, summary: dict) -> None:
        """manifest.DamagedFileError unless every table eval.json (`summary`) lists is as it
        lists it."""
        for name in EVALUATION_TABLES:
            manifest.read_evaluation_file(self.folder, name, summary)

    def check_world(self, config: dict, world: str, summary: dict) -> None:
        """storage.CorruptFileError (one line, with `world_remedy`) unless `summary`, this
        eval-in-`world`/ evaluation's eval.json, records `world` as declared now and lists every
        table of an evaluation, each as it lies there (size and SHA-256)."""
        remedy = world_remedy(self.trial_dir, world)
        # What makes the world: a world setting added to the project later (and filled in for
        # older files, config_file.py) does not make an evaluation stale.
        expected = json.loads(json.dumps(_world_identity(world_record(config, world))))
        recorded = summary.get("eval_world")
        if not isinstance(recorded, dict) or _world_identity(recorded) != expected:
            raise EvalWorldMismatch(
                f"{self.path} is not an evaluation in the {world} world as declared now "
                f"(experiments/trial_dir/eval_worlds.py): {remedy}"
            )
        listed = summary.get(manifest.EVAL_FILES_KEY)
        for name in EVALUATION_TABLES:
            try:
                size, sha256 = listed[name]  # type: ignore[index]
                entry = manifest.Entry(int(size), str(sha256))
            except (KeyError, TypeError, ValueError):
                raise manifest.DamagedFileError(
                    f"{self.path} does not list {name}: {remedy}"
                ) from None
            manifest.Manifest(self.folder, {name: entry}, 0).read_bytes(self.folder / name, remedy)


def _world_identity(record: dict) -> dict:
    """What makes an eval world of a world record: its name, backend and switches."""
    world = record.get("world")
    switches = {s: world.get(s) for s in SWITCHES} if isinstance(world, dict) else None
    return {"name": record.get("name"), "grasp": record.get("grasp"), "switches": switches}


def world_remedy(trial_dir: Path, world: str) -> str:
    """The command that (re)makes a trial's evaluation in eval world `world`."""
    return f"`playroom eval {trial_dir} --world {world}` evaluates it there"


def in_world(trial_dir: Path, world: str) -> Evaluation:
    """A trial's evaluation in eval world `world` other than its own: its eval-in-WORLD/."""
    return Evaluation(trial_dir, trial_dir / eval_world_dir(world))


def evaluation_files(summary: dict, tables: dict[str, bytes], config: dict) -> dict[str, bytes]:
    """The files of an evaluation of the trial whose config.json is `config`, by name, eval.json
    last: it vouches for the tables (storage.write_files). `tables`: each table's bytes by its
    kind (TABLES). eval.json lists the tables with their sizes and checksums, so that a reader
    refuses a table lost, damaged or left from another evaluation, and records its own checksum
    and the trial's identity, so that a reader refuses it damaged or another trial's
    (eval_record.py). A word's best distance (and so a median) is infinite until the learner's
    first voice movement: eval.json, standard JSON, holds null for it
    (experiments/analysis/results.py reads it back as infinity); `summary` itself keeps the
    numbers."""
    files = {TABLES[kind]: data for kind, data in tables.items()}
    summary[manifest.EVAL_FILES_KEY] = manifest.evaluation_files(files)
    return {**files, EVAL_FILE: eval_record.evaluation_json(summary, config)}
