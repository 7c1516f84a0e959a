"""What makes a folder of trial directories one batch, checked by every reader of a batch
(`playroom report`, compare, ablations, experiments/analysis/logs.py `read_batch_logs`): the
trials of each group (a grasp backend, a babbling mode) ran with the same settings but the seed,
no seed twice (a trial copied twice would count double), and the batch's record (batch.json)
says they are its trials."""

from __future__ import annotations

import json
from pathlib import Path

from experiments.analysis.batch_record import RecordMismatch, check_trials_agree
from experiments.trial_dir.config_file import config_differences


class BatchMismatch(ValueError):
    """Trials of a batch directory that cannot be read as one batch; one line says which."""


def group_label(grasp: str, babbling: str, mixed_babbling: bool) -> str:
    """A group's name: its grasp backend, and its babbling mode where a batch mixes modes."""
    return f"{grasp} {babbling}" if mixed_babbling else grasp


def shared_config(config: dict) -> dict:
    """A trial's config without its seed: what must agree within a group."""
    shared = json.loads(json.dumps(config))  # a deep copy, so the seed is popped from a copy
    shared.get("trial", {}).pop("seed", None)
    return shared


def groups(dirs: list[Path], configs: list[dict]) -> dict[str, list[int]]:
    """Group label -> the positions of its trials in `dirs` (configs read, older settings
    added)."""
    mixed = len({c["trial"]["babbling"] for c in configs}) > 1
    found: dict[str, list[int]] = {}
    for i, c in enumerate(configs):
        label = group_label(c["trial"]["grasp"], c["trial"]["babbling"], mixed)
        found.setdefault(label, []).append(i)
    return dict(sorted(found.items()))


def check_group(label: str, dirs: list[Path], configs: list[dict]) -> None:
    """BatchMismatch unless every setting but the seed agrees and the seeds are distinct."""
    reference = shared_config(configs[0])
    for d, config in zip(dirs[1:], configs[1:], strict=True):
        differences = config_differences(reference, shared_config(config))
        if differences:
            key, a, b = differences[0]  # the first is enough to find the culprit
            raise BatchMismatch(
                f"trials of mismatched configs in group {label}: {dirs[0].name} and "
                f"{d.name} differ in {key} ({a!r} != {b!r})"
            )
    seen: dict[int, Path] = {}
    for d, config in zip(dirs, configs, strict=True):
        seed = config["trial"]["seed"]
        if seed in seen:
            raise BatchMismatch(
                f"seed {seed} appears twice in group {label} ({seen[seed].name}, {d.name}): "
                "a trial copied twice would count double"
            )
        seen[seed] = d


def check_batch(
    batch_dir: Path,
    dirs: list[Path],
    configs: list[dict],
    unfinished: frozenset[Path] = frozenset(),
) -> None:
    """BatchMismatch (one line) unless the trials `dirs` (with their `configs`) of `batch_dir`
    are one batch (module docstring). Trials of `unfinished` may be being extended: their
    length is not compared, nor are they checked against the record."""
    try:
        check_trials_agree(batch_dir, [d for d in dirs if d not in unfinished])
    except RecordMismatch as exc:
        raise BatchMismatch(str(exc)) from None
    if unfinished:
        configs = [json.loads(json.dumps(c)) for c in configs]
        for c in configs:
            c["trial"].pop("iterations", None)
    for label, members in groups(dirs, configs).items():
        check_group(label, [dirs[i] for i in members], [configs[i] for i in members])
