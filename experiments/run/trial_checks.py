"""Reading a trial directory back only when it is whole, and saying truly what is not.

- A checkpoint is used only if it is the trial's own (its identity, log_layout.trial_identity)
  and readable; the newest is preferred, the previous one is the fallback of a resume only.
- The log chunks a checkpoint covers must be present, the trial's own (the identity they
  carry, if they carry one) and hold what their names say: a lost chunk cannot be regenerated
  (except by running the trial again from scratch), so whatever finds one stops, names it, and
  changes nothing.
- Temporary files of writers killed mid-write are litter, removed by every writer under the
  lock (a resume, an evaluation), never results.
- Logs of the old layout (chunks of both kinds side by side in log/) are read as they are, and
  brought into their kinds' folders by a resume (experiments/run/old_logs.py).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from experiments import manifest, storage
from experiments.config_file import UnknownSettingError, check_known, with_added_settings
from experiments.file_names import (
    BACKEND_FILE,
    CHECKPOINT_FILE,
    CONFIG_FILE,
    DAMAGED_CHECKPOINT_FILE,
    LOG_KINDS,
    PREVIOUS_CHECKPOINT_FILE,
)
from experiments.log_layout import (
    LOST_CHUNK_REMEDY,
    DuplicateChunkError,
    ForeignChunkError,
    check_chunk,
    chunk_path,
    chunk_paths,
    identity_text,
    trial_identity,
)
from experiments.run import memory_segments
from experiments.run.old_logs import move_old_chunks
from experiments.run.trial_files import WORDS_LOG_PERIOD, TrialError, fresh_trial_parts
from learner.agent import Agent
from sim import Playroom


def check_identity(path: Path, meta: dict, config: dict) -> None:
    """TrialError if the checkpoint at `path` belongs to another trial than `config`'s.
    A checkpoint without identity (written before checkpoints carried one) is taken as the
    trial's: the caller says so where it can."""
    found, own = meta.get("identity"), trial_identity(config)
    if found is None or found == own:
        return
    raise TrialError(
        f"{path.name} belongs to another trial ({identity_text(found)}) than "
        f"{path.parent} ({identity_text(own)}); refusing to mix them"
    )


def restore_checkpoint(
    trial_dir: str | os.PathLike,
    agent: Agent,
    room: Playroom,
    name: str = CHECKPOINT_FILE,
    *,
    config: dict,
) -> dict:
    """Load a trial's checkpoint, with the memory segments it names, into `agent` and `room`;
    returns the checkpoint's metadata with 'best_word_distance' added. CorruptFileError if it
    or a segment cannot be read or restored; TrialError if either belongs to another trial
    than `config`'s."""
    path = Path(trial_dir) / name
    if not path.exists():
        raise storage.CorruptFileError(f"{path} is missing")
    arrays, meta = storage.read_arrays(path)
    check_identity(path, meta, config)
    try:
        arrays = memory_segments.with_rows(path, arrays, meta)
    except memory_segments.ForeignSegmentError as exc:
        raise TrialError(str(exc)) from None
    try:
        prefix = memory_segments.AGENT
        agent_state = {k.removeprefix(prefix): v for k, v in arrays.items() if k.startswith(prefix)}
        agent.load_state_dict(agent_state)
        room.set_state({**meta["room"], "physics": arrays["room/physics"]})
        meta["best_word_distance"] = arrays["best_word_distance"].copy()
    except (KeyError, ValueError, TypeError) as exc:
        raise storage.CorruptFileError(f"{path} cannot be restored ({exc})") from None
    return meta


# How a trial's agent and room at iteration 0 are built, new ones at each call.
Build = Callable[[], tuple[Agent, Playroom]]


def restore_newest(
    trial_dir: str | os.PathLike,
    config: dict,
    first: tuple[Agent, Playroom] | None = None,
    build: Build | None = None,
) -> tuple[Agent, Playroom, dict, str | None]:
    """A trial's newest usable checkpoint, restored into fresh parts (`first`, built already,
    then `build`'s, by default those `config` makes): (agent, room, meta, fallback), `fallback`
    None when checkpoint.npz was used, else one line saying what is wrong with it (missing, or
    damaged). TrialError if neither checkpoint can be used (naming both, and what is wrong with
    each), or if the one read belongs to another trial."""
    trial_dir = Path(trial_dir)
    problems = []
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        # A restore that failed half-way may have changed them: each try starts afresh.
        if first is not None:
            (agent, room), first = first, None
        else:
            agent, room = fresh_trial_parts(config) if build is None else build()
        try:
            meta = restore_checkpoint(trial_dir, agent, room, name, config=config)
        except storage.CorruptFileError as exc:
            problems.append(" ".join(str(exc).split()))
            continue
        return agent, room, meta, (problems[0] if problems else None)
    raise TrialError(
        f"{trial_dir} cannot be restored: {problems[0]}; {problems[1]}. Nothing was changed: "
        "a trial without a readable checkpoint can only be run again from scratch, into a new "
        "directory"
    )


def load_trial(trial_dir: str | os.PathLike) -> tuple[dict, Agent, Playroom, dict]:
    """A finished or checkpointed trial, read-only: (config, agent, room, checkpoint meta).
    TrialError unless its newest checkpoint is its own and readable, and its logs up to it,
    its memory segments and backend.json whole and as its manifest recorded them: what is
    derived from it (an evaluation, a report) would not be the trial's."""
    trial_dir = Path(trial_dir)
    if not (trial_dir / CONFIG_FILE).exists():
        raise TrialError(f"{trial_dir} holds no trial ({CONFIG_FILE} is missing)")
    if not any((trial_dir / n).exists() for n in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE)):
        raise TrialError(f"{trial_dir} has no checkpoint yet")
    config = with_added_settings(storage.read_json(trial_dir / CONFIG_FILE))
    try:
        check_known(config, trial_dir / CONFIG_FILE)
    except UnknownSettingError as exc:
        raise TrialError(str(exc)) from None
    agent, room, meta, fallback = restore_newest(trial_dir, config)
    if fallback is not None:
        # Only the resume may fall back: it rewrites the logs past the previous checkpoint.
        raise TrialError(
            f"{fallback}; `playroom run --out {trial_dir} --resume` continues the trial from "
            f"{PREVIOUS_CHECKPOINT_FILE} (iteration {meta['iteration']}), then evaluate it"
        )
    if meta["iteration"] == 0:
        raise TrialError(f"{trial_dir} has not reached its first checkpoint yet")
    if check_files(trial_dir, meta, config) is None:
        manifest.warn_unchecked(trial_dir)
    return config, agent, room, meta


def check_files(trial_dir: Path, meta: dict, config: dict) -> manifest.Manifest | None:
    """TrialError unless the logs and backend.json of the trial whose checkpoint has metadata
    `meta` are whole and as its manifest recorded them (the memory segments are checked when the
    checkpoint is restored); the manifest, None for a trial from before manifests."""
    recorded = _recorded(trial_dir, meta)
    check_logs(trial_dir, int(meta["iteration"]), config, recorded)
    if recorded is not None:
        _check_backend(trial_dir, recorded)
    return recorded


def _recorded(trial_dir: Path, meta: dict) -> manifest.Manifest | None:
    """The manifest of a restored checkpoint (its chain already read once by the restore)."""
    try:
        return manifest.read_manifest(trial_dir, meta)
    except storage.CorruptFileError as exc:
        raise TrialError(_first_line(exc)) from None


def _check_backend(trial_dir: Path, recorded: manifest.Manifest) -> None:
    """TrialError unless backend.json is as the trial recorded it (when it recorded one)."""
    path = trial_dir / BACKEND_FILE
    if path in recorded:
        try:
            recorded.read_bytes(path, f"`playroom run --out {trial_dir} --resume` regenerates it")
        except storage.CorruptFileError as exc:
            raise TrialError(str(exc)) from None


def _chunks(trial_dir: Path, kind: str) -> dict[int, Path]:
    """The chunks of one kind of log, of both layouts (experiments/log_layout.py);
    TrialError for a chunk found in both."""
    try:
        return chunk_paths(trial_dir, kind)
    except DuplicateChunkError as exc:
        raise TrialError(f"{exc}; nothing was changed") from None


def check_logs(
    trial_dir: str | os.PathLike,
    iteration: int,
    config: dict | None = None,
    recorded: manifest.Manifest | None = None,
) -> None:
    """TrialError naming the first log chunk, of those a checkpoint at `iteration` covers, that
    is missing, unreadable, of another trial than `config`'s (the trial's config.json if None),
    not as the checkpoint's manifest (`recorded`, None for a trial from before manifests)
    recorded it, not recorded there, or holds other rows than its name and period say: the
    iterations chunks hold 0 to `iteration` - 1 without a gap, each words chunk the multiples of
    WORDS_LOG_PERIOD its iterations chunk reaches. Chunks starting at `iteration` or later are
    work past the checkpoint (a resume rewrites them) and are not looked at. Chunks of both
    layouts (log/iterations/ and log/words/, or side by side in log/) are read."""
    trial_dir = Path(trial_dir)
    if config is None:
        config = with_added_settings(storage.read_json(trial_dir / CONFIG_FILE))
    own = trial_identity(config)
    found = {
        kind: {s: p for s, p in _chunks(trial_dir, kind).items() if s < iteration}
        for kind in LOG_KINDS
    }
    if recorded is not None:
        stray = [p for kind in LOG_KINDS for p in found[kind].values() if p not in recorded]
        if stray:
            raise TrialError(_lost(f"{stray[0]} is not among the files the trial recorded"))
    start = 0
    while start < iteration:
        if start not in found["iterations"]:
            path = chunk_path(trial_dir, "iterations", start)
            end = min((s for s in found["iterations"] if s > start), default=iteration)
            raise TrialError(_lost(f"{path} is missing (iterations {start} to {end - 1})"))
        path = found["iterations"][start]
        end = start + _check_rows(
            path, range(start, iteration), (trial_dir, own), recorded, whole=False
        )
        # The words rows this period reached: the multiples of the period in (start, end].
        reached = range(
            (start // WORDS_LOG_PERIOD + 1) * WORDS_LOG_PERIOD, end + 1, WORDS_LOG_PERIOD
        )
        words = found["words"].pop(start, chunk_path(trial_dir, "words", start))
        if reached and not words.exists():
            raise TrialError(_lost(f"{words} is missing (words at {reached[0]} to {reached[-1]})"))
        if words.exists():
            _check_rows(words, reached, (trial_dir, own), recorded, whole=True)
        start = end
    for words in found["words"].values():
        raise TrialError(_lost(f"{words} starts where no iterations chunk starts"))


def _check_rows(
    path: Path,
    expected: range,
    trial: tuple[Path, dict],
    recorded: manifest.Manifest | None,
    whole: bool,
) -> int:
    """The number of rows of a log chunk of `trial` (its directory and identity), whose
    iterations must be the first of `expected` (all of them if `whole`), and whose bytes must be
    those the trial's manifest recorded (if it has one); TrialError naming the chunk
    otherwise."""
    try:
        data = path.read_bytes()
        check_chunk(path, trial[1], trial[0])  # first: it names a foreign chunk as such
        if recorded is not None:
            recorded.verify(path, data, "")
        rows = storage.read_column(path, "iteration", data)
    except (ForeignChunkError, manifest.DamagedFileError) as exc:
        raise TrialError(_lost(str(exc).removesuffix(": "))) from None
    except storage.CorruptFileError as exc:
        raise TrialError(_lost(_first_line(exc))) from None
    if not rows or rows != list(expected[: len(rows)]) or (whole and len(rows) != len(expected)):
        wanted = f"iterations {expected[0]} on" if expected else "no rows"
        raise TrialError(_lost(f"{path} does not hold what its name says ({wanted})"))
    return len(rows)


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__


def _lost(problem: str) -> str:
    """One line: a log chunk that is not whole (`problem` names it), and the only ways back."""
    return f"{problem}: {LOST_CHUNK_REMEDY}; nothing was changed"


def _alive(pid: int) -> bool:
    """Whether a process `pid` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's
        return True
    return True


def is_litter(name: str) -> bool:
    """Whether a file named `name` is a temporary file of a writer that no longer runs."""
    pid = storage.temporary_writer(name)
    return pid is not None and not _alive(pid)


def remove_litter(trial_dir: str | os.PathLike) -> list[str]:
    """Remove the temporary files that writers killed mid-write (storage.write_bytes) left in a
    trial directory, wherever they lie in it (its memory/, log/, manifest/, an eval world's
    folder...); returns their paths relative to the directory.

    Called under the directory's lock: every writer of the trial's own files (run, eval, a
    batch task) holds it, so such a file there was left by a dead writer. A live process is
    still spared: a writer that takes no lock (a video rendered into the directory) may own
    it. A spared file is never taken for a result either (experiments/run/trial.py's derived
    files leave temporary files out)."""
    trial_dir = Path(trial_dir)
    removed = []
    for path in sorted(trial_dir.rglob(".*.tmp")):
        if is_litter(path.name):
            path.unlink(missing_ok=True)
            removed.append(path.relative_to(trial_dir).as_posix())
    return removed


# What a resume starts from: the agent, the room, the checkpoint's meta and its manifest.
Restored = tuple[Agent, Playroom, dict, manifest.Manifest | None]


def prepare_resume(
    trial_dir: Path, config: dict, parts: tuple[Agent, Playroom], build: Build, notices: list[str]
) -> Restored | None:
    """What a resume starts from: (agent, room, checkpoint meta, its manifest or None for a
    checkpoint from before manifests) of the newest usable checkpoint, restored into `parts`
    (fresh ones `build` builds where a restore fails half-way),
    whose logs are whole and as recorded, or None to start from iteration 0 (no checkpoint and
    no logs yet). Everything is checked before anything is changed; then a damaged newest
    checkpoint is kept as checkpoint.damaged.npz, the litter of killed writers removed, old
    logs moved into their folders and the work past the checkpoint (log chunks, memory
    segments, manifest files) dropped: the run writes it again. Appends to `notices` one line
    per thing done or noticed. TrialError if the trial cannot be resumed (the message says why
    and what can be done)."""
    newest = trial_dir / CHECKPOINT_FILE
    if not newest.exists() and not (trial_dir / PREVIOUS_CHECKPOINT_FILE).exists():
        # A run writes a checkpoint at iteration 0 before its first chunk (experiments/
        # trial.py): logs without one are a trial whose checkpoints were lost.
        chunks = [p for kind in LOG_KINDS for p in _chunks(trial_dir, kind).values()]
        if chunks:
            raise TrialError(
                f"{trial_dir} holds {len(chunks)} log chunk(s) but no checkpoint "
                f"({CHECKPOINT_FILE} and {PREVIOUS_CHECKPOINT_FILE} are missing): resuming "
                "would restart it from iteration 0 and delete its logs; refusing. Restore the "
                "checkpoints, or run the trial again from scratch into a new directory"
            )
        notices.append(f"{trial_dir} holds no checkpoint yet: starting it from iteration 0")
        restored = None
    else:
        agent, room, meta, fallback = restore_newest(trial_dir, config, parts, build)
        recorded = _recorded(trial_dir, meta)
        check_logs(trial_dir, int(meta["iteration"]), config, recorded)
        restored = agent, room, meta, recorded
        if "identity" not in meta:
            notices.append(
                "the checkpoint predates trial identities (no seed or config hash in it): "
                "taken as this trial's; the next checkpoint carries one"
            )
        if fallback is not None:
            kept = ""
            if newest.exists():  # damaged, not missing: kept for whoever looks into it
                os.replace(newest, trial_dir / DAMAGED_CHECKPOINT_FILE)
                kept = f" (the damaged one is kept as {DAMAGED_CHECKPOINT_FILE})"
            notices.append(
                f"{fallback}; resumed from the previous checkpoint ({PREVIOUS_CHECKPOINT_FILE}), "
                f"at iteration {meta['iteration']}{kept}"
            )
    litter = remove_litter(trial_dir)
    if litter:
        notices.append(
            f"removed {len(litter)} temporary file(s) of a killed writer: {', '.join(litter)}"
        )
    moved = move_old_chunks(trial_dir, config)
    if moved:
        notices.append(
            f"moved {moved} log chunk(s) of the old layout (log/iterations-*.parquet, "
            "log/words-*.parquet) into log/iterations/ and log/words/"
        )
    _drop_work_past(trial_dir, 0 if restored is None else int(restored[2]["iteration"]))
    return restored


def _drop_work_past(trial_dir: Path, iteration: int) -> None:
    """Delete what was written past the checkpoint at `iteration` (the lost work's log chunks,
    memory segments and manifest files), which the resumed run writes again."""
    for kind in LOG_KINDS:
        for start, chunk in _chunks(trial_dir, kind).items():
            if start >= iteration:
                chunk.unlink()
    memory_segments.drop_segments_past(trial_dir, iteration)
    manifest.drop_past(trial_dir, iteration)
