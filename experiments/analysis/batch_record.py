"""What a batch directory records of the batch that wrote it (batch.json, written by
`playroom batch`): the size of the study's random reference its reports play, which the
batch's profile sets (experiments/batches/profiles/*.json, "study_reference_commands"), and
the settings its trials must have been run with, which its reports check."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from pathlib import Path

from experiments.batch_files import BATCH_FILE
from experiments.trial_dir import storage
from experiments.trial_dir.reading import open_for_reading


class RecordMismatch(ValueError):
    """Trials of a batch directory that its record says another batch than they ran, or a
    record that cannot be read."""


def read_batch_record(batch_dir: str | os.PathLike) -> dict | None:
    """A batch's record (batch.json); None for a batch written before records. RecordMismatch
    (one line, saying what to do) for one that cannot be read or is not a record: a damaged
    record is never taken for none, which would report the batch as another (the study's
    reference size instead of its profile's, its trials unchecked)."""
    path = Path(batch_dir) / BATCH_FILE
    if not path.exists():
        return None
    try:
        record = storage.read_json(path)
    except (storage.CorruptFileError, OSError) as exc:
        problem = " ".join(str(exc).split())
    else:
        if isinstance(record, dict):
            return record
        problem = f"{path} is not a batch record"
    raise RecordMismatch(
        f"{problem}: rerun `playroom batch` into {batch_dir} with the profile or config that "
        f"made it (after removing {path.name}: the batch then checks its trials against that "
        "run and writes the record again)"
    )


def recorded_reference_commands(batch_dirs: Iterable[str | os.PathLike]) -> int | None:
    """The largest study reference size (random commands per ring) the batches record, so that
    a page setting a small batch beside a large one measures both as the large one asks; None
    where none records one (a batch written before batch.json: the study's size applies).
    RecordMismatch for a record that cannot be read, or that is missing from a batch whose
    trials were written after records existed (`check_not_lost`)."""
    sizes = []
    for batch_dir in batch_dirs:
        record = read_batch_record(batch_dir)
        if record is None:
            check_not_lost(Path(batch_dir))
        size = record.get("study_reference_commands") if isinstance(record, dict) else None
        if isinstance(size, int) and not isinstance(size, bool) and size > 0:
            sizes.append(size)
    return max(sizes, default=None)


def check_not_lost(batch_dir: Path) -> None:
    """RecordMismatch (one line, saying how to write it again) for a batch directory without
    batch.json whose trials record a manifest (experiments/trial_dir/manifest.py): every version
    that wrote manifests wrote batch.json too, so its record was lost (or the folder was put
    together by hand), and the reference size its profile set is unknown; only a batch from before
    records is reported at the study's size without one."""
    if (batch_dir / BATCH_FILE).exists() or not batch_dir.is_dir():
        return
    for trial_dir in sorted(batch_dir.iterdir()):
        trial = open_for_reading(trial_dir)
        if trial.is_trial() and trial.records_manifest():
            raise RecordMismatch(
                f"{batch_dir} has no {BATCH_FILE}, though its trials were written by a version "
                f"that writes one ({trial_dir.name} records a manifest of its files, which no "
                "earlier version did), so the reference size its profile set is unknown: rerun "
                "`playroom batch` into it with the profile or config that made it (complete "
                f"trials are kept, not run again, and {BATCH_FILE} is written again), or give "
                "--study-reference-commands"
            )


# The trial settings a record fixes for every trial (a record field -> config.json's "trial").
_SAME = ("iterations", "stick_return", "preset", "voice", "overrides")
# The record's lists: each trial's setting is one of them.
_ONE_OF = {"grasps": "grasp", "babbling": "babbling", "seeds": "seed"}


def _disagreement(record: dict, trial: dict, n_placements: object) -> str | None:
    """How a trial's settings (config.json's "trial", older settings added) differ from what
    the record runs, the first difference in words; None when none does."""
    for name, setting in _ONE_OF.items():
        allowed = record.get(name)
        if isinstance(allowed, list) and trial.get(setting) not in allowed:
            return f"{setting} {trial.get(setting)!r}, which the record's {name} do not hold"
    expected = {name: record[name] for name in _SAME if name in record}
    if "checkpoint_every" in record and "iterations" in record:  # a trial checkpoints at its end
        expected["checkpoint_every"] = min(record["checkpoint_every"], record["iterations"])
    for name, value in expected.items():
        if trial.get(name) != value:
            return f"{name}={_shown(trial.get(name))} where the record says {_shown(value)}"
    placements = record.get("eval_placements")
    if placements is not None and n_placements is not None and n_placements != placements:
        return f"eval_placements={n_placements} where the record says {placements}"
    return None


def _shown(value: object) -> str:
    text = value if isinstance(value, str) else json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def check_trials_agree(batch_dir: str | os.PathLike, trial_dirs: Iterable[Path]) -> None:
    """RecordMismatch (one line) naming the trials of `batch_dir` whose config.json (or
    evaluation) disagrees with the batch's record (batch.json): a batch rerun into the same
    directory with other settings, before `playroom batch` refused it, left such a mix. A
    batch without a record is not checked (one written before batch.json, or a folder of
    trials run one by one); a record that cannot be read is refused (`read_batch_record`).
    Each eval.json is read checked (experiments/trial_dir/eval_record.py): one that is not as
    recorded is left to the reader that needs it to name, not taken for another batch's."""
    path = Path(batch_dir) / BATCH_FILE
    record = read_batch_record(batch_dir)
    if record is None:
        return
    found = []
    for trial_dir in trial_dirs:
        reading = open_for_reading(trial_dir)
        try:
            config = reading.config()
            trial = config["trial"]
            summary = reading.evaluation().summary(config, "", warn=False)
        except (storage.CorruptFileError, OSError, KeyError, TypeError, AttributeError):
            continue  # the reader that needs the file says what is wrong with it
        why = _disagreement(record, trial, summary.get("n_placements"))
        if why is not None:
            found.append((trial_dir.name, why))
    if found:
        (name, why), more = found[0], len(found) - 1
        others = f" (and {more} more trial(s))" if more else ""
        raise RecordMismatch(
            f"{name} in {batch_dir} ran with {why} ({path.name}){others}: the directory mixes "
            "two batches' trials; report each batch from a directory of its own"
        )
