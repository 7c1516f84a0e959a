"""Where everything of a trial directory lies, by name, and which trial each log chunk is: the
one description that the writer (experiments/trial_dir/writing.py) writes by and every reader
(experiments/trial_dir/reading.py, a resume's checks) reads by.

A trial directory holds:
- `config.json`: every setting (trial, world, voice, learner), the package version, the seed;
- `checkpoint.npz`: the agent's state, the room's and every random generator's, rewritten
  every `checkpoint_every` iterations and at the end, with the one before it kept beside it
  as `checkpoint.prev.npz`: a damaged newest checkpoint costs at most two periods;
- `memory/rows-NNNNNNNN.npz`: the rows the models' memories stored over the checkpoint period
  starting at iteration NNNNNNNN, each row written once, before the checkpoint that names the
  segments it is made of (memory_segments.py; checkpoints written before
  segments hold every row themselves);
- `log/iterations/chunk-NNNNNNNN.parquet`: one row per iteration (motor space, chosen model,
  events, goal, outcome, every model's interest), one file per checkpoint period, starting at
  iteration NNNNNNNN;
- `log/words/chunk-NNNNNNNN.parquet`: every 100 iterations, the best distance reached so far to
  each of the 6 words, in the chunk of the period that reaches them;
  every row of both carries its source (trial, seed, backend, voice), and every chunk its
  trial's identity, as checkpoints do; where the chunks lie is below, and what every column
  holds log_schema.py, which the writer and every reader follow
  (trials of the old layout too: log/iterations-NNNNNNNN.parquet and log/words-NNNNNNNN.parquet
  side by side);
- `log/README.txt`: which folder of log/ to read (a reader of all of log/ stops on it);
- `provenance.json`: the machine, libraries and commit that computed each stretch of
  iterations, one entry per run or resume (provenance.py);
- `backend.json`: what the grasp backend declares of itself (its reach, its capabilities),
  written when the trial first computes (backend_record.py), and `summary.json`, where its run
  ended, written with its last checkpoint: its records (RECORDS, records.py);
- `manifest/files-NNNNNNNN.json`: every data file's size and SHA-256, one file per checkpoint
  (manifest.py);
- `.lock`: the lock of its one writer (lock.py).
These are the trial itself (TRIAL_ENTRIES). Everything else in it (its evaluation, eval.json and
its tables, and those of other worlds in eval-in-WORLD/; timing; videos) is derived from the
trial at some iteration, and moved aside into `stale-at-NNNNNNNN/` when the trial is extended.

Where the chunks lie. Each kind of log has its own folder, one chunk per checkpoint period:
`log/iterations/chunk-NNNNNNNN.parquet`, `log/words/chunk-NNNNNNNN.parquet`. Trials written
before the kinds had folders hold `log/iterations-NNNNNNNN.parquet` and
`log/words-NNNNNNNN.parquet` side by side; both layouts are read here (a resume moves the old
chunks into the folders: old_logs.py).

Which trial a chunk belongs to. Each chunk carries its trial's identity in its Parquet schema's
metadata, as each checkpoint does in its own (config_file.trial_identity: the seed and a hash of
the settings that make the trial), so that a chunk copied from another trial is told apart
(`check_chunk`). It is written as the table's `attrs[CHUNK_IDENTITY_KEY]`, which pandas keeps
there (JSON under b"PANDAS_ATTRS") and gives back to a reader of the chunk. Chunks written
before they carried one are taken as their trial's, as they always were.

What the rows hold: log_schema.py, which declares every column of both kinds once.

Names, and pure functions of paths and dicts, reading only: no simulator, no learner.
"""

from __future__ import annotations

import os
from pathlib import Path

# The trial itself -----------------------------------------------------------------------
CONFIG_FILE = "config.json"
CHECKPOINT_FILE = "checkpoint.npz"
PREVIOUS_CHECKPOINT_FILE = "checkpoint.prev.npz"
# Where a damaged newest checkpoint is kept when a resume falls back past it.
DAMAGED_CHECKPOINT_FILE = "checkpoint.damaged.npz"
# The models' memories, each row written once: one segment per checkpoint period that stored
# rows, memory/rows-NNNNNNNN.npz, NNNNNNNN the iteration the period starts at; a checkpoint
# names the newest segment it is made of (experiments/trial_dir/memory_segments.py).
MEMORY_DIR = "memory"
MEMORY_SEGMENT_PREFIX = "rows-"
LOG_DIR = "log"
# The logs, each kind in its own folder of LOG_DIR, one chunk per checkpoint period:
# log/iterations/chunk-NNNNNNNN.parquet and log/words/chunk-NNNNNNNN.parquet, NNNNNNNN the
# iteration the chunk starts at, so that `pd.read_parquet("TRIAL/log/iterations")` reads one kind.
LOG_KINDS = ("iterations", "words")
LOG_CHUNK_PREFIX = "chunk-"
# Trials written before the kinds had folders hold log/iterations-NNNNNNNN.parquet and
# log/words-NNNNNNNN.parquet side by side: read as they are, moved into the folders on resume.
# A text file in LOG_DIR, beside the kinds' folders: it says which folder to read, and a reader
# of the whole of LOG_DIR (`pd.read_parquet("TRIAL/log")`) stops on it, naming it, instead of
# mixing the two kinds' rows.
LOG_README_FILE = "README.txt"
OLD_LOG_CHUNK_PATTERN = r"(?P<kind>iterations|words)-(?P<start>[0-9]{8})\.parquet"
# Where the machine, libraries and commit of each stretch of iterations are recorded
# (experiments/trial_dir/provenance.py), and where one that cannot be read is kept aside.
PROVENANCE_FILE = "provenance.json"
DAMAGED_PROVENANCE_FILE = "provenance.damaged.json"
# Every data file the trial wrote, with its size and SHA-256, one file per checkpoint:
# manifest/files-NNNNNNNN.json, NNNNNNNN the checkpoint's iteration (manifest.py).
MANIFEST_DIR = "manifest"
# The trial's records: small JSON files a run writes of itself, each recorded in the manifest,
# checked against it by every reader that checks a trial whole or reads the record, and
# regenerated by the next run when lost or damaged if it computes the same bytes again
# (records.py). A new record is one line here, by its kind, and the code that computes it.
RECORDS = {
    # What the trial's grasp backend declares of itself (its reach, its capabilities), written
    # when the trial first computes, for analysis to read (backend_record.py).
    "backend": "backend.json",
    # Where the trial's run ended: its iteration, counts and best distance to each word
    # (records.summary_record), written with its last checkpoint: readable without NumPy.
    "summary": "summary.json",
}
BACKEND_FILE = RECORDS["backend"]
# The lock of the directory's one writer (experiments/trial_dir/lock.py).
LOCK_FILE = ".lock"
TRIAL_ENTRIES = (
    CONFIG_FILE,
    CHECKPOINT_FILE,
    PREVIOUS_CHECKPOINT_FILE,
    DAMAGED_CHECKPOINT_FILE,
    MEMORY_DIR,
    MANIFEST_DIR,
    LOG_DIR,
    LOCK_FILE,
    PROVENANCE_FILE,
    DAMAGED_PROVENANCE_FILE,
    *RECORDS.values(),
)
# Derived files of a shorter run, moved aside when a trial is extended.
STALE_PREFIX = "stale-at-"

# Derived from the trial ---------------------------------------------------------------------
EVAL_FILE = "eval.json"
COMPETENCE_FILE = "competence.parquet"
VOCAL_FILE = "vocal.parquet"
# The tests of the study's own measure (experiments/measure/study_measure.py).
STUDY_TESTS_FILE = "study-tests.parquet"
# The tables an evaluation writes beside eval.json, which lists them with their checksums.
EVALUATION_TABLES = (COMPETENCE_FILE, VOCAL_FILE, STUDY_TESTS_FILE)
# Seconds and iterations of the batch task that last ran the trial.
TIMING_FILE = "timing.json"
# The trial's final agent evaluated in another world than its own (eval_worlds.py):
# eval-in-NAME/, holding an evaluation's eval.json and EVALUATION_TABLES. Derived like the rest:
# moved aside with them when the trial is extended.
EVAL_WORLD_PREFIX = "eval-in-"

# A deep-RL baseline's run (experiments/baseline/run.py): its settings, then its policies' record
# (each policy a policy-toyK.zip beside it); its evaluation is a trial's (the files above).
BASELINE_FILE = "baseline.json"
TRAINING_FILE = "training.json"


def eval_world_dir(world: str) -> str:
    """The folder of a trial directory that holds its evaluation in eval world `world`."""
    return f"{EVAL_WORLD_PREFIX}{world}"


def log_chunk_name(start: int) -> str:
    """The name of the log chunk that starts at iteration `start`, in its kind's folder."""
    return f"{LOG_CHUNK_PREFIX}{start:08d}.parquet"


def memory_segment_name(start: int) -> str:
    """The name of the memory segment of the checkpoint period that starts at iteration
    `start`, in MEMORY_DIR."""
    return f"{MEMORY_SEGMENT_PREFIX}{start:08d}.npz"


def manifest_name(iteration: int) -> str:
    """The name of the manifest file the checkpoint at `iteration` names, in MANIFEST_DIR."""
    return f"files-{iteration:08d}.json"


# What log/README.txt says (LOG_README_FILE: why it is there).
LOG_README = """\
This folder holds a trial's logs, one folder per kind, one Parquet chunk per checkpoint period:
  iterations/  one row per iteration          pd.read_parquet("TRIAL/log/iterations")
  words/       every 100 iterations, the best distance reached so far to each word
                                              pd.read_parquet("TRIAL/log/words")
The kinds have different rows: read one of the folders, not this one (this file stops a reader
of the whole folder before it mixes them). Every row names its trial, seed, backend and voice.
With the project installed: `from experiments.analysis.logs import read_log, read_batch_logs`;
the columns are described in experiments/trial_dir/log_schema.py.
"""


# The key of a chunk's table attrs that holds its trial's identity, and where pandas keeps a
# table's attrs in the Parquet schema's metadata (DataFrame.to_parquet, read_parquet).
CHUNK_IDENTITY_KEY = "playroom.trial"
# What a user can do about a log chunk that is missing, damaged or foreign: said after it.
LOST_CHUNK_REMEDY = (
    "the logs of a trial cannot be regenerated except by running it again from scratch (into "
    "a new directory, with the settings in its config.json) or restored from a backup"
)


def check_kind(kind: str) -> None:
    """ValueError (one line) unless `kind` is a kind of log."""
    if kind not in LOG_KINDS:
        raise ValueError(f"unknown log kind {kind!r}: one of {', '.join(LOG_KINDS)}")


def kind_folder(kind: str) -> str:
    """The folder of one kind of log, relative to the trial directory (a name: the reader or
    writer joins it to the directory)."""
    check_kind(kind)
    return f"{LOG_DIR}/{kind}"


def chunk_file(kind: str, start: int) -> str:
    """Where the chunk of `kind` that starts at iteration `start` is written, relative to the
    trial directory."""
    return f"{kind_folder(kind)}/{log_chunk_name(start)}"


def is_trial_dir(directory: str | os.PathLike) -> bool:
    """Whether a folder is a trial directory: `playroom run` writes its config.json and log/
    (the module docstring). Another tool's folder with a config.json is not one."""
    directory = Path(directory)
    return (directory / CONFIG_FILE).is_file() and (directory / LOG_DIR).is_dir()
