"""A trial's `provenance.json`: who computed each stretch of its iterations, one entry per run
or resume, `{"from_iteration": N, "record": provenance.machine_record()}` (the record is null
for iterations computed before provenance was recorded), and what readers show of it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from experiments.trial_dir import provenance, storage
from experiments.trial_dir.layout import DAMAGED_PROVENANCE_FILE, PROVENANCE_FILE
from experiments.trial_dir.provenance import SHORT_FIELDS


def read_entries(trial_dir: str | os.PathLike) -> list[dict] | None:
    """The entries of a trial's provenance.json, oldest first; None when it has none (a trial
    from before provenance was recorded). CorruptFileError when it cannot be read."""
    path = Path(trial_dir) / PROVENANCE_FILE
    if not path.exists():
        return None
    entries = storage.read_json(path)
    valid = isinstance(entries, list) and all(
        isinstance(e, dict)
        and isinstance(e.get("from_iteration"), int)
        and (e.get("record") is None or isinstance(e.get("record"), dict))
        for e in entries
    )
    if not valid:
        raise storage.CorruptFileError(f"{path} is not a list of provenance entries")
    return entries


def record_start(
    trial_dir: str | os.PathLike, iteration: int, inputs: dict[str, str] | None = None
) -> list[str]:
    """Append this machine's entry, computing from `iteration` on, to the trial's
    provenance.json (written atomically; the caller holds the trial's lock). `inputs`: data
    the trial computes from that is the user's, not the project's (DIVA's map: its digest).
    Entries from `iteration` on are dropped: a resume discarded what they computed. Returns the
    lines to tell the user: the code, machine or libraries changed since the previous entry, or
    a damaged provenance.json was kept aside."""
    trial_dir = Path(trial_dir)
    notices = []
    try:
        entries = read_entries(trial_dir) or []
    except storage.CorruptFileError as exc:
        os.replace(trial_dir / PROVENANCE_FILE, trial_dir / DAMAGED_PROVENANCE_FILE)
        notices.append(
            f"{exc}; kept as {DAMAGED_PROVENANCE_FILE}, the machines of iterations before "
            f"{iteration} are not recorded in the new {PROVENANCE_FILE}"
        )
        entries = []
    entries = [e for e in entries if e["from_iteration"] < iteration]
    if iteration > 0 and not entries:  # computed before provenance was recorded
        entries = [{"from_iteration": 0, "record": None}]
    record = provenance.machine_record()
    if inputs:
        record["inputs"] = dict(inputs)
    entries.append({"from_iteration": iteration, "record": record})
    storage.write_json(trial_dir / PROVENANCE_FILE, entries)
    previous = entries[-2] if len(entries) > 1 else None
    if previous is not None and previous["record"] is not None:
        changes = provenance.bit_differences(previous["record"], record)
        if changes:
            shown = ", ".join(changes[:3]) + (
                f" and {len(changes) - 3} more" if changes[3:] else ""
            )
            notices.append(
                f"code, machine or libraries changed since iteration {previous['from_iteration']} "
                f"({shown}): its iterations from {iteration} on may differ in their last bits "
                f"from a run before it (recorded in {PROVENANCE_FILE})"
            )
    return notices


def computed_on(trial_dir: str | os.PathLike) -> list[dict[str, Any]]:
    """Who computed a trial: one dict per stretch of iterations (consecutive entries of the
    same short record are one stretch), each {"from_iteration", "status", **SHORT_FIELDS};
    status 'recorded', 'not recorded' (no record: an older trial) or 'unreadable'."""
    blank = dict.fromkeys(SHORT_FIELDS, "")
    try:
        entries = read_entries(trial_dir)
    except storage.CorruptFileError:
        return [{"from_iteration": 0, "status": "unreadable", **blank}]
    if entries is None:
        return [{"from_iteration": 0, "status": "not recorded", **blank}]
    stretches: list[dict[str, Any]] = []
    for entry in entries:
        short = provenance.short_record(entry["record"])
        row = {
            "from_iteration": entry["from_iteration"],
            "status": "not recorded" if short is None else "recorded",
            **(short or blank),
        }
        same = stretches and all(stretches[-1][k] == row[k] for k in ("status", *SHORT_FIELDS))
        if not same:
            stretches.append(row)
    return stretches


def computed_on_line(trial_dir: str | os.PathLike) -> str:
    """Where a trial was computed, in one line (`playroom eval` prints it)."""
    stretches = computed_on(trial_dir)
    if stretches[0]["status"] == "unreadable":
        return f"computed on: unknown, {PROVENANCE_FILE} cannot be read"
    if len(stretches) == 1 and stretches[0]["status"] == "not recorded":
        return f"computed on: not recorded (no {PROVENANCE_FILE}: the trial predates it)"
    parts = []
    for s in stretches:
        where = "not recorded" if s["status"] == "not recorded" else provenance.describe(s)
        parts.append(f"{where} from iteration {s['from_iteration']}")
    return "computed on " + "; ".join(parts)
