"""A trial directory opened for reading: `open_for_reading(path)`, one of the package's two
faces (the other is writing.py). Every reader of a trial (analysis, reports, measures, videos,
the baseline, a batch's checks, the Python API) reads it through the `TrialReading` this
returns, part by part, each part checked as it is read and read once:

- `config()`: config.json, with the settings added since it was written (config_file.py);
- `log(kind, columns)`: one of its logs, every chunk checked against the trial's manifest and
  by the identity it carries (log_reading.py);
- `evaluation()`, `evaluation_in(world)`: its evaluations, eval.json and the tables it lists
  checked (evaluation.py);
- `checkpoint_meta()`, `checkpoint_arrays()`, `agent_state()`, `restored(parts_of)`: its newest
  checkpoint, its metadata, its arrays with the memory segments it names (the agent's part of
  them), or restored into an agent and room the caller builds, the trial checked whole first
  (checkpoint.py, checks.py);
- `backend()`, `record(kind)`, `computed_on()` (or its one line), `timing()`: backend.json,
  any of its records (layout.RECORDS: backend.json, summary.json), provenance.json,
  timing.json;
- `file_manifest()`: what its newest checkpoint recorded of every file, for a reader that
  checks the files itself.

What readers outside the package name of a trial's records comes through here too (the names
imported `as` themselves below): the log kinds (`check_kind`), what backend.json declares
(`CAPABILITIES`) and the reach the study's rules are measured by (`study_reach`), eval.json's
key for scenes kept clear of the stick (`SCENES_KEY`), the warning of a trial read unchecked
(written before manifests) and its one line per batch.

Opening reads nothing: a part is read when asked for, so that a reader pays only for what it
reads (a report reads no checkpoint, an evaluation no evaluation). No simulator is loaded.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from experiments.trial_dir import (
    backend_record,
    checkpoint,
    manifest,
    memory_segments,
    records,
    storage,
)
from experiments.trial_dir.backend_record import CAPABILITIES as CAPABILITIES
from experiments.trial_dir.backend_record import study_reach as study_reach
from experiments.trial_dir.checks import check_files, recorded_manifest
from experiments.trial_dir.config_file import (
    UnknownSettingError,
    check_known,
    trial_identity,
    with_added_settings,
)
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.eval_record import SCENES_KEY as SCENES_KEY
from experiments.trial_dir.eval_worlds import OWN, own_world
from experiments.trial_dir.evaluation import Evaluation, in_world
from experiments.trial_dir.layout import (
    BACKEND_FILE,
    CHECKPOINT_FILE,
    CONFIG_FILE,
    EVAL_FILE,
    LOG_DIR,
    MANIFEST_DIR,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
    TIMING_FILE,
    is_trial_dir,
    kind_folder,
    manifest_name,
    memory_segment_name,
)
from experiments.trial_dir.layout import check_kind as check_kind
from experiments.trial_dir.log_reading import read_log_checked
from experiments.trial_dir.manifest import (
    UncheckedTrialWarning as UncheckedTrialWarning,
)
from experiments.trial_dir.manifest import warn_unchecked as warn_unchecked
from experiments.trial_dir.manifest import warn_unchecked_once as warn_unchecked_once
from experiments.trial_dir.provenance_file import computed_on, computed_on_line

# What marks a folder as a trial directory (layout.is_trial_dir), as messages say it.
TRIAL_MARKS = f"{CONFIG_FILE} and {LOG_DIR}/"
# What marks a trial as evaluated (its eval.json), as messages say it.
EVALUATION_MARK = EVAL_FILE


@dataclass
class TrialReading:
    """A trial directory opened for reading (the module's docstring): its parts, each read
    when first asked for."""

    dir: Path
    _config: dict | None = field(default=None, repr=False)

    # config.json ---------------------------------------------------------------------------
    @property
    def config_path(self) -> Path:
        """config.json, as messages name it."""
        return self.dir / CONFIG_FILE

    def has_config(self) -> bool:
        """Whether config.json is there (a folder of a trial, or of one being made)."""
        return self.config_path.exists()

    def no_trial_line(self) -> str:
        """What a reader says of a folder without config.json: it holds no trial."""
        return f"{self.dir} holds no trial ({CONFIG_FILE} is missing)"

    def is_trial(self) -> bool:
        """Whether the folder is a trial directory (`playroom run` wrote its config.json and
        log/); another tool's folder with a config.json is not one."""
        return is_trial_dir(self.dir)

    def config_json(self) -> Any:
        """config.json as it lies (storage.CorruptFileError if it is not JSON; OSError if it
        cannot be read)."""
        return storage.read_json(self.config_path)

    def config(self) -> dict:
        """config.json with every setting added since it was written set to the value older
        trials ran with (config_file.with_added_settings); read once."""
        if self._config is None:
            self._config = with_added_settings(self.config_json())
        return self._config

    def checked_config(self) -> dict:
        """`config()`, config_file.UnknownSettingError naming a setting no version wrote."""
        config = self.config()
        check_known(config, self.config_path)
        return config

    # Logs ----------------------------------------------------------------------------------
    def log(
        self, kind: str = "iterations", columns: Sequence[str] | None = None
    ) -> tuple[pd.DataFrame, bool]:
        """(one log, every chunk checked: log_reading.read_log_checked; whether the manifest
        checked it, False for a trial from before manifests, which the caller says)."""
        return read_log_checked(self.dir, kind, columns)

    def log_folder(self, kind: str) -> Path:
        """The folder of one kind of log, as messages name it."""
        return self.dir / kind_folder(kind)

    # The checkpoint ------------------------------------------------------------------------
    def has_checkpoint(self) -> bool:
        """Whether it holds a checkpoint, the newest or the previous one."""
        return checkpoint.has_checkpoint(self.dir)

    @property
    def checkpoint_path(self) -> Path:
        """The newest checkpoint, as messages and measures name it."""
        return self.dir / CHECKPOINT_FILE

    def has_newest_checkpoint(self) -> bool:
        return self.checkpoint_path.exists()

    def segment_path(self, start: int) -> Path:
        """The memory segment of the checkpoint period that starts at iteration `start`."""
        return self.dir / MEMORY_DIR / memory_segment_name(start)

    def manifest_path(self, iteration: int) -> Path:
        """The manifest file of the checkpoint at `iteration`."""
        return self.dir / MANIFEST_DIR / manifest_name(iteration)

    def checkpoint_meta(self) -> dict:
        """The newest checkpoint's metadata, its arrays not read (storage.CorruptFileError if it
        is missing or cannot be read)."""
        return storage.read_meta(self.dir / CHECKPOINT_FILE)

    def checkpoint_arrays(self) -> tuple[dict[str, np.ndarray], dict]:
        """The newest checkpoint's arrays, with every model's memory rows its segments hold,
        and its metadata (checkpoint.newest_arrays)."""
        return checkpoint.newest_arrays(self.dir)

    def agent_state(self) -> dict[str, np.ndarray]:
        """The agent's state in the newest checkpoint, every model's memory rows among it,
        by the keys of Agent.state_dict (`checkpoint_arrays`)."""
        return memory_segments.agent_part(self.checkpoint_arrays()[0])

    def file_manifest(self) -> manifest.Manifest | None:
        """What the newest checkpoint recorded of every file (manifest.trial_manifest: None,
        with an UncheckedTrialWarning, for a trial from before manifests)."""
        return manifest.trial_manifest(self.dir)

    def check_checkpoint_identity(self, meta: dict, config: dict) -> None:
        """TrialError if the newest checkpoint (of metadata `meta`) is another trial's."""
        checkpoint.check_identity(self.dir / CHECKPOINT_FILE, meta, trial_identity(config))

    def records_manifest(self) -> bool:
        """Whether it records a manifest of its files (manifest.py), which every version since
        manifests writes, whatever its checkpoints say."""
        return manifest.recorded_any(self.dir)

    def check_files(self, meta: dict, config: dict) -> None:
        """TrialError unless the logs and backend.json a checkpoint of metadata `meta` covers
        are whole and as its manifest recorded them (checks.check_files)."""
        recorded = recorded_manifest(self.dir, meta)
        check_files(self.dir, meta, trial_identity(config), recorded)

    def restored(
        self, parts_of: Callable[[dict], tuple[checkpoint.A, checkpoint.R]]
    ) -> tuple[dict, checkpoint.A, checkpoint.R, dict]:
        """A finished or checkpointed trial, read-only: (config, agent, room, checkpoint meta),
        the agent and room `parts_of(config)` builds, restored from the newest checkpoint.
        TrialError unless its newest checkpoint is its own and readable, and its logs up to it,
        its memory segments and backend.json whole and as its manifest recorded them: what is
        derived from it (an evaluation, a report) would not be the trial's."""
        if not self.has_config():
            raise TrialError(self.no_trial_line())
        if not self.has_checkpoint():
            raise TrialError(f"{self.dir} has no checkpoint yet")
        try:
            config = self.checked_config()
        except UnknownSettingError as exc:
            raise TrialError(str(exc)) from None
        identity = trial_identity(config)
        agent, room, meta, recorded, fallback = checkpoint.restore_newest(
            self.dir, identity, None, lambda: parts_of(config)
        )
        if fallback is not None:
            # Only the resume may fall back: it rewrites the logs past the previous checkpoint.
            raise TrialError(
                f"{fallback}; `playroom run --out {self.dir} --resume` continues the trial from "
                f"{PREVIOUS_CHECKPOINT_FILE} (iteration {meta['iteration']}), then evaluate it"
            )
        if meta["iteration"] == 0:
            raise TrialError(f"{self.dir} has not reached its first checkpoint yet")
        check_files(self.dir, meta, identity, recorded)
        if recorded is None:
            manifest.warn_unchecked(self.dir)
        return config, agent, room, meta

    def kept_iteration(self) -> object | None:
        """The iteration its newest readable checkpoint records (the newest, else the previous
        one), as recorded; None without one."""
        for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
            if (self.dir / name).exists():
                try:
                    return storage.read_meta(self.dir / name)["iteration"]
                except (storage.CorruptFileError, KeyError, TypeError):
                    continue
        return None

    def progress(self) -> tuple[int, int]:
        """(iteration of the newest readable checkpoint, bytes it holds on disk): checkpoint.py."""
        return checkpoint.progress(self.dir)

    # Evaluations ---------------------------------------------------------------------------
    def evaluation(self, folder: str | os.PathLike | None = None) -> Evaluation:
        """Its evaluation in `folder` (by default its own, in the trial directory)."""
        return Evaluation(self.dir, self.dir if folder is None else Path(folder))

    def evaluation_in(self, world: str) -> Evaluation:
        """Its evaluation in eval world `world`: its own (eval.json in the trial directory)
        where `world` is OWN or the trial's own world (eval_worlds.own_world, from
        `config()`), else its eval-in-WORLD/. EvalWorldError for an unknown world or a
        config.json that names no preset."""
        if world == OWN or own_world(self.config(), world):
            return self.evaluation()
        return in_world(self.dir, world)

    def evaluation_elsewhere(self, world: str) -> Evaluation:
        """Its evaluation in eval-in-WORLD/, whether or not `world` is its own."""
        return in_world(self.dir, world)

    # The records it keeps of itself ---------------------------------------------------------
    def backend(self, config: dict) -> dict:
        """What its backend declared (backend.json, checked against the manifest; older trials:
        computed from `config`, its config.json): backend_record.read_record."""
        return backend_record.read_record(self.dir, config)

    def record(self, kind: str) -> Any | None:
        """Its record of `kind` (a key of layout.RECORDS: "backend", "summary"), checked
        against its manifest (records.read_checked); None when it has none."""
        return records.read_checked(self.dir, kind)

    def has_backend_record(self) -> bool:
        return (self.dir / BACKEND_FILE).exists()

    def computed_on(self) -> list[dict[str, Any]]:
        """Who computed it, stretch by stretch (provenance_file.computed_on)."""
        return computed_on(self.dir)

    def computed_on_line(self) -> str:
        """Who computed it, in one line (`playroom eval` prints it)."""
        return computed_on_line(self.dir)

    @property
    def timing_path(self) -> Path:
        """timing.json, as messages name it."""
        return self.dir / TIMING_FILE

    def timing(self) -> Any | None:
        """timing.json as it lies (the seconds and iterations of the batch task that last ran
        the trial); None when the trial did not record it. storage.CorruptFileError if it is
        not JSON."""
        path = self.timing_path
        return storage.read_json(path) if path.exists() else None


def open_for_reading(trial_dir: str | os.PathLike) -> TrialReading:
    """A trial directory opened for reading (the module's docstring). Nothing is read yet."""
    return TrialReading(Path(trial_dir))


def trials_in(folder: str | os.PathLike) -> list[Path]:
    """The trial directories a folder (a batch directory) holds, by name."""
    return sorted(d for d in Path(folder).iterdir() if d.is_dir() and is_trial_dir(d))


def is_trial(folder: str | os.PathLike) -> bool:
    """Whether a folder is a trial directory (`TrialReading.is_trial`)."""
    return is_trial_dir(folder)
