"""An evaluation's eval.json, recorded so that a reader can trust it as it trusts a trial's
data files (experiments/trial_dir/manifest.py): its own checksum, and the trial it belongs to.

eval.json vouches for its tables (it lists their sizes and SHA-256: manifest.EVAL_FILES_KEY),
but nothing else vouches for it: it is written after the trial's last checkpoint (a trial's
evaluation is derived, moved aside when the trial is extended, and an eval world's is made at
any time later), so no checkpoint's manifest can record it. So it records itself:

- `CHECKSUM_KEY`: the size and SHA-256 (manifest.Entry) of the JSON text of every other entry
  of the file, as `storage.json_bytes` writes it. A reader parses the file, takes that entry
  out, writes the rest again the same way and compares, and checks that the file's bytes are
  the very text the writer made of both: a flipped bit anywhere, in a number, in the checksum
  itself or in a space, is refused, so the check needs nothing outside the file.
- `IDENTITY_KEY`: the identity of the trial evaluated (experiments/trial_dir/config_file.py
  `trial_identity`, as its checkpoints and log chunks carry it), beside the `seed` and `grasp`
  eval.json has always held. A reader compares all three with the trial's config.json: another
  trial's evaluation copied in whole, tables and all, is intact but not this trial's.

`read_evaluation` is the one reader of eval.json: every reader of an evaluation (reports,
compare, ladder, ablations, the analysis readers, a batch's checks of what it may skip) goes
through it, and a damaged or foreign eval.json is refused in one line naming it and what to do
(evaluate again). It checks eval.json before any table it lists, so that the damage is laid at
the right file's door. An eval.json written before these entries is read as it is, with one
warning (manifest.UncheckedEvaluationWarning), as a trial written before manifests is; its
`seed` and `grasp` are still compared.
"""

from __future__ import annotations

import os
from pathlib import Path

from experiments.trial_dir import manifest, storage
from experiments.trial_dir.config_file import identity_text, trial_identity
from experiments.trial_dir.layout import EVAL_FILE, EVAL_WORLD_PREFIX

# eval.json's entry of its own checksum ([size, sha256] of the text of the other entries).
CHECKSUM_KEY = "checksum"
# eval.json's entry of the identity of the trial evaluated ({"seed", "config"}).
IDENTITY_KEY = "trial_identity"
# eval.json's entry saying its scenes were placed clear of the stick (`playroom eval
# --scenes-clear-of-stick`, experiments/measure/evaluation.py), written only then: an
# evaluation of the default scenes is the file it always was.
SCENES_KEY = "scenes_clear_of_stick"


def evaluation_json(summary: dict, config: dict) -> bytes:
    """eval.json's bytes: `summary` (a number that is not finite as null, standard JSON) with
    the identity of the trial of config.json `config`, which is added to `summary` too, and
    the checksum of both (the module's docstring)."""
    summary[IDENTITY_KEY] = trial_identity(config)
    body = storage.finite_or_null(summary)
    checksum = manifest.entry_of(storage.json_bytes(body)).as_json()
    return storage.json_bytes({**body, CHECKSUM_KEY: checksum})


def evaluation_remedy(trial_dir: str | os.PathLike, folder: str | os.PathLike) -> str:
    """What a user does about a trial's evaluation in `folder` (the trial directory, or its
    eval-in-WORLD/) that is damaged, missing or another's: evaluate it again."""
    trial_dir, folder = Path(trial_dir), Path(folder)
    if folder == trial_dir:
        return f"evaluate the trial again (`playroom eval {trial_dir}`, or rerun its batch)"
    world = folder.name.removeprefix(EVAL_WORLD_PREFIX)
    return f"evaluate it again (`playroom eval {trial_dir} --world {world}`, or rerun its batch)"


def read_evaluation(
    folder: str | os.PathLike, config: dict, remedy: str, warn: bool = True
) -> dict:
    """The summary eval.json in `folder` holds (its checksum entry taken out), after checking
    it: intact (its checksum) and the evaluation of the trial whose config.json is `config`
    (its seed, grasp and identity). manifest.DamagedFileError (one line naming the file, then
    `remedy`) otherwise, or for a file missing or not JSON. An eval.json written before it
    recorded its checksum is read unchecked, with an UncheckedEvaluationWarning if `warn`."""
    path = Path(folder) / EVAL_FILE
    try:
        data = path.read_bytes()
        summary = storage.json_from_bytes(data, path)
    except FileNotFoundError:
        raise manifest.DamagedFileError(f"{path} is missing: {remedy}") from None
    except storage.CorruptFileError as exc:
        raise manifest.DamagedFileError(f"{exc}: {remedy}") from None
    if not isinstance(summary, dict):
        raise manifest.DamagedFileError(f"{path} is not an evaluation summary: {remedy}")
    recorded = summary.pop(CHECKSUM_KEY, None)
    if recorded is None and IDENTITY_KEY not in summary:
        if warn:
            manifest.warn_unchecked(path, manifest.UncheckedEvaluationWarning)
    else:
        _check_intact(path, data, summary, recorded, remedy)
    _check_trial(path, summary, config, remedy)
    return summary


def _check_intact(path: Path, data: bytes, summary: dict, recorded: object, remedy: str) -> None:
    """DamagedFileError unless `recorded` is the checksum of `summary`'s JSON text and `data`,
    the file's bytes, are the text the writer made of both: a changed byte that changes no
    value read (a space, a digit past a float's precision) is damage too."""
    unusable = manifest.DamagedFileError(
        f"{path} records no usable checksum of itself (damaged): {remedy}"
    )
    if not isinstance(recorded, list) or len(recorded) != 2:
        raise unusable
    try:
        entry = manifest.Entry(int(recorded[0]), str(recorded[1]))
    except (TypeError, ValueError):
        raise unusable from None
    try:
        written = storage.json_bytes({**summary, CHECKSUM_KEY: recorded})
        body = storage.json_bytes(summary)
    except ValueError:  # a NaN or infinity, which the writer never writes
        written, body = b"", b""
    if written != data or manifest.entry_of(body) != entry:
        raise manifest.DamagedFileError(
            f"{path} is damaged (what it holds is not what it recorded when it was written): "
            f"{remedy}"
        )


def _check_trial(path: Path, summary: dict, config: dict, remedy: str) -> None:
    """DamagedFileError unless `summary` evaluates the trial of `config`: its seed and grasp,
    and its identity where it records one."""
    trial = config["trial"]
    own = (trial["seed"], trial["grasp"])
    found = (summary.get("seed"), summary.get("grasp"))
    if found != own:
        raise manifest.DamagedFileError(
            f"{path} is the evaluation of another trial (seed {found[0]}, grasp {found[1]}) "
            f"than the one it lies in (seed {own[0]}, grasp {own[1]}): {remedy}"
        )
    if IDENTITY_KEY in summary and summary[IDENTITY_KEY] != trial_identity(config):
        raise manifest.DamagedFileError(
            f"{path} is the evaluation of another trial ({identity_text(summary[IDENTITY_KEY])}) "
            f"than the one it lies in ({identity_text(trial_identity(config))}): {remedy}"
        )
