"""Every file a trial directory or a batch directory holds, by name, in one place.

A trial directory (experiments/run/trial.py writes it) holds the trial itself: its settings,
checkpoints, memory segments, logs, provenance and lock (TRIAL_ENTRIES); everything else in it
was derived from the trial at some iteration (its evaluation, its timing) and is moved aside
into `stale-at-NNNNNNNN/` when the trial is extended. A batch directory holds one trial directory
per trial, and the pages written about it.
"""

from __future__ import annotations

# The trial itself -----------------------------------------------------------------------
CONFIG_FILE = "config.json"
CHECKPOINT_FILE = "checkpoint.npz"
PREVIOUS_CHECKPOINT_FILE = "checkpoint.prev.npz"
# Where a damaged newest checkpoint is kept when a resume falls back past it.
DAMAGED_CHECKPOINT_FILE = "checkpoint.damaged.npz"
# The models' memories, each row written once: one segment per checkpoint period that stored
# rows, memory/rows-NNNNNNNN.npz, NNNNNNNN the iteration the period starts at; a checkpoint
# names the newest segment it is made of (experiments/run/memory_segments.py).
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
# (experiments/provenance.py), and where one that cannot be read is kept aside.
PROVENANCE_FILE = "provenance.json"
DAMAGED_PROVENANCE_FILE = "provenance.damaged.json"
# Every data file the trial wrote, with its size and SHA-256, one file per checkpoint:
# manifest/files-NNNNNNNN.json, NNNNNNNN the checkpoint's iteration (experiments/manifest.py).
MANIFEST_DIR = "manifest"
# What the trial's grasp backend declares of itself (its reach, its capabilities), written when
# the trial first computes, for analysis to read (experiments/backend_record.py).
BACKEND_FILE = "backend.json"
# The lock of the directory's one writer (experiments/run/lock.py).
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
    BACKEND_FILE,
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
# The trial's final agent evaluated in another world than its own (experiments/eval_worlds.py):
# eval-in-NAME/, holding an evaluation's eval.json and EVALUATION_TABLES. Derived like the rest:
# moved aside with them when the trial is extended.
EVAL_WORLD_PREFIX = "eval-in-"

# A deep-RL baseline's run (experiments/baseline/run.py): its settings, then its policies' record
# (each policy a policy-toyK.zip beside it); its evaluation is a trial's (the files above).
BASELINE_FILE = "baseline.json"
TRAINING_FILE = "training.json"

# What a batch is: its spec as `playroom batch` last ran it (experiments/batches/spec.py).
BATCH_FILE = "batch.json"
# What a batch's submitter writes into the batch directory for its workers to read back (the
# same path on a shared filesystem), one per run, removed when the run ends: NAME.format(run).
WORKER_TOKEN_FILE = ".workers-{}.token"

# Pages about a batch ------------------------------------------------------------------------
REPORT_FILE = "report.html"
COMPARISON_FILE = "comparison.html"
ABLATION_TABLE_FILE = "ablations.md"
ABLATION_CSV_FILE = "ablations.csv"
ABLATION_FIGURE_FILE = "ablations.png"
# The numbers a report or comparison page shows, machine-readable, written with the page
# (experiments/report/summary.py): nested JSON, and the same numbers as one long CSV table.
SUMMARY_JSON_FILE = "summary.json"
SUMMARY_CSV_FILE = "summary.csv"


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
