"""Nothing in a trial directory is lost or silently mixed: a resume, an evaluation and a batch
rerun read back only a whole trial (its own checkpoint, logs complete up to it), say truly what
is wrong otherwise, and change nothing then; the litter of killed writers is never a result."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest
from trial_states import same_state

from experiments.batches.runner import is_complete, run_and_evaluate
from experiments.cli.main import main
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.run.trial_parts import load_trial
from experiments.trial_dir import storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    CONFIG_FILE,
    DAMAGED_CHECKPOINT_FILE,
    EVAL_FILE,
    LOCK_FILE,
    LOG_DIR,
    MANIFEST_DIR,
    PREVIOUS_CHECKPOINT_FILE,
    eval_world_dir,
    manifest_name,
)

SEED, TOTAL, PERIOD = 7, 300, 100
SETTINGS = TrialSettings(iterations=TOTAL, seed=SEED, checkpoint_every=PERIOD)
LONGER = TrialSettings(iterations=TOTAL + PERIOD, seed=SEED, checkpoint_every=PERIOD)


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """A finished, evaluated trial: 300 kinematic iterations, checkpoints every 100. Tests
    write into copies of it (`_copy`)."""
    out = tmp_path_factory.mktemp("base") / "trial"
    run_trial(out, SETTINGS, progress=False)
    evaluate_trial(out, EvaluationSettings(n_placements=1))
    return out


def _copy(base, tmp_path):
    out = tmp_path / "trial"
    shutil.copytree(base, out)
    return out


def _contents(out) -> dict:
    """Every file of a trial directory and its bytes (the lock file names its last holder)."""
    return {p: p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != LOCK_FILE}


def _cli(capsys, *argv: str) -> tuple[int, list[str]]:
    """`playroom ARGV` in this process: (exit code, lines written to stderr)."""
    code = main(list(argv))
    return code, capsys.readouterr().err.strip().splitlines()


def _resume_args(out) -> list[str]:
    return ["run", "--out", str(out), "--resume", "--quiet", "--iterations", str(TOTAL)] + [
        "--seed",
        str(SEED),
        "--checkpoint-every",
        str(PERIOD),
    ]


def _truncate(path) -> None:
    path.write_bytes(path.read_bytes()[:300])


def task_failure(out, settings) -> str:
    """The line a batch rerun's task for the trial in `out` fails with: raised, or returned (a
    batch task may return the failures a retry would repeat instead of raising them)."""
    try:
        result = run_and_evaluate(str(out), settings, eval_placements=1)
    except TrialError as exc:
        return str(exc)
    error = getattr(result, "error", None)
    assert isinstance(error, str), result
    return error


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


# 1. Logs without a usable checkpoint ---------------------------------------------------------
def test_resume_refuses_logs_without_checkpoints_and_deletes_nothing(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    (out / CHECKPOINT_FILE).unlink()
    (out / PREVIOUS_CHECKPOINT_FILE).unlink()
    before = _contents(out)
    code, err = _cli(capsys, *_resume_args(out))
    assert code == 2 and len(err) == 1
    assert "no checkpoint" in err[0] and "refusing" in err[0]
    assert _contents(out) == before


def test_a_trial_killed_before_its_first_checkpoint_restarts_from_0(tmp_path):
    out = tmp_path / "t"
    run_trial(out, SETTINGS, progress=False)
    shutil.rmtree(out / LOG_DIR)
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        (out / name).unlink()
    notices: list[str] = []
    trial = run_trial(out, SETTINGS, resume=True, progress=False, notify=notices.append)
    assert trial.iteration == TOTAL and "starting it from iteration 0" in notices[0]


def test_killed_between_the_first_log_chunk_and_its_checkpoint_resumes_to_the_same(base, tmp_path):
    # The first chunk is on disk, its checkpoint is not: the one at iteration 0 is the newest.
    out = tmp_path / "t"
    run_trial(
        out, TrialSettings(iterations=PERIOD, seed=SEED, checkpoint_every=PERIOD), progress=False
    )
    os.replace(out / PREVIOUS_CHECKPOINT_FILE, out / CHECKPOINT_FILE)
    assert storage.read_arrays(out / CHECKPOINT_FILE)[1]["iteration"] == 0
    run_trial(out, SETTINGS, resume=True, progress=False)
    same_state(out, base)


# 2. A checkpoint carries its trial's identity ------------------------------------------------
def test_the_identity_is_the_seed_and_the_settings_that_make_the_trial():
    from experiments.trial_dir.config_file import trial_identity

    config = {
        "trial": {"seed": 3, "iterations": 10, "grasp": "kinematic"},
        "world": {"a": 1.5},
        "package_version": "0.1.0",
    }
    same = {**config, "trial": {**config["trial"], "iterations": 99}, "package_version": "9.9"}
    assert trial_identity(same) == trial_identity(config)  # extensible, and not the trial
    assert trial_identity(config)["seed"] == 3
    for other in ({**config, "world": {"a": 1.25}}, {**config, "trial": {"seed": 4}}):
        assert trial_identity(other) != trial_identity(config)


@pytest.mark.parametrize("setting", [{"seed": 8}, {"seed": SEED, "stick_return": "never"}])
def test_a_checkpoint_of_another_trial_is_refused(base, tmp_path, capsys, setting):
    other = tmp_path / "other"
    settings = TrialSettings(iterations=PERIOD, checkpoint_every=PERIOD, **setting)
    run_trial(other, settings, progress=False)
    out = _copy(base, tmp_path)
    shutil.copy(other / CHECKPOINT_FILE, out / CHECKPOINT_FILE)
    before = _contents(out)
    with pytest.raises(TrialError, match="belongs to another trial") as exc:
        run_trial(out, LONGER, resume=True, progress=False)
    assert f"(seed {setting['seed']}, config " in str(exc.value)
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1 and "belongs to another trial" in err[0]
    assert not is_complete(out)
    assert _contents(out) == before


def test_a_checkpoint_without_identity_is_taken_with_a_notice(base, tmp_path):
    from experiments.trial_dir.config_file import trial_identity

    out = _copy(base, tmp_path)
    arrays, meta = storage.read_arrays(out / CHECKPOINT_FILE)
    del meta["identity"]
    storage.write_arrays(out / CHECKPOINT_FILE, arrays, meta)
    notices: list[str] = []
    run_trial(out, LONGER, resume=True, progress=False, notify=notices.append)
    assert any("predates trial identities" in n for n in notices)
    meta = storage.read_arrays(out / CHECKPOINT_FILE)[1]
    assert meta["identity"] == trial_identity(storage.read_json(out / CONFIG_FILE))


# 3. Completeness checks read what they rely on -----------------------------------------------
LOG_DAMAGE = {
    "missing chunk": ("iterations/chunk-00000100.parquet", "is missing", lambda p: p.unlink()),
    "truncated chunk": ("iterations/chunk-00000100.parquet", "damaged or truncated", _truncate),
    "missing words": ("words/chunk-00000100.parquet", "is missing", lambda p: p.unlink()),
}


@pytest.mark.parametrize("damage", LOG_DAMAGE, ids=list(LOG_DAMAGE))
def test_a_lost_log_chunk_stops_resume_eval_and_a_batch_rerun(base, tmp_path, capsys, damage):
    name, problem, hurt = LOG_DAMAGE[damage]
    out = _copy(base, tmp_path)
    hurt(out / LOG_DIR / name)
    before = _contents(out)
    code, err = _cli(capsys, *_resume_args(out))
    assert code == 2 and len(err) == 1
    assert name in err[0] and problem in err[0] and "from scratch" in err[0]
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1 and name in err[0]
    # A batch rerun does not skip it, and its task names the chunk.
    assert not is_complete(out)
    assert name in task_failure(out, SETTINGS)
    assert _contents(out) == before


def test_a_truncated_eval_json_is_evaluated_again_by_a_batch_rerun(base, tmp_path):
    out = _copy(base, tmp_path)
    assert is_complete(out)
    _truncate(out / EVAL_FILE)
    assert not is_complete(out)
    run_and_evaluate(str(out), SETTINGS, eval_placements=1)
    assert storage.read_json(out / EVAL_FILE)["evaluated_at_iteration"] == TOTAL
    assert is_complete(out)


# 4. Left-over temporary files ----------------------------------------------------------------
def test_temporary_files_of_killed_writers_are_removed_and_never_results(base, tmp_path):
    out = _copy(base, tmp_path)
    dead = _dead_pid()
    litter = [
        out / f".{CHECKPOINT_FILE}.{dead}.tmp",
        out / LOG_DIR / "iterations" / f".chunk-00000200.parquet.{dead}.tmp",
        out / LOG_DIR / f".iterations-00000200.parquet.{dead}.tmp",  # of the old layout
    ]
    for path in litter:
        path.write_bytes(b"half a file")
    # A live writer that takes no lock (a video rendered into the directory) keeps its file.
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        spared = out / f".video.mp4.{live.pid}.tmp"
        spared.write_bytes(b"being written")
        notices: list[str] = []
        run_trial(out, LONGER, resume=True, progress=False, notify=notices.append)
    finally:
        live.kill()
        live.wait()
    assert not any(path.exists() for path in litter) and spared.exists()
    stale = sorted(p.name for p in (out / f"stale-at-{TOTAL:08d}").iterdir())
    assert stale and all(not name.endswith(".tmp") for name in stale)
    assert EVAL_FILE in stale
    assert any("temporary file" in n and f".{CHECKPOINT_FILE}.{dead}.tmp" in n for n in notices)


@pytest.mark.parametrize("writer", ["resume", "eval"])
def test_f5_a_killed_writers_temporary_file_is_removed_wherever_it_lies(base, tmp_path, writer):
    out = _copy(base, tmp_path)
    dead = _dead_pid()
    (out / eval_world_dir("physical")).mkdir()
    litter = [
        out / MANIFEST_DIR / f".{manifest_name(TOTAL)}.{dead}.tmp",  # a checkpoint's manifest
        out / eval_world_dir("physical") / f".{EVAL_FILE}.{dead}.tmp",  # a cross-evaluation's
        out / f".write-test.{dead}.tmp",  # the probe of whether the directory can be written
    ]
    for path in litter:
        path.write_bytes(b"half a file")
    notices: list[str] = []
    if writer == "resume":
        run_trial(out, SETTINGS, resume=True, progress=False, notify=notices.append)
    else:
        evaluate_trial(out, EvaluationSettings(n_placements=1), notify=notices.append)
    assert not any(path.exists() for path in litter)
    removed = f"{MANIFEST_DIR}/.{manifest_name(TOTAL)}.{dead}.tmp"
    assert any("temporary file" in n and removed in n for n in notices), notices


def test_a_new_trials_folder_left_by_a_killed_first_write_is_started_again(tmp_path):
    # Killed (SIGKILL) while writing its config.json: the folder holds the lock and a temporary.
    out = tmp_path / "t"
    out.mkdir()
    (out / LOCK_FILE).write_text("1\n")
    left = out / f".{CONFIG_FILE}.{_dead_pid()}.tmp"
    left.write_bytes(b'{"tri')
    short = TrialSettings(iterations=PERIOD, seed=SEED, checkpoint_every=PERIOD)
    assert run_trial(out, short, progress=False).iteration == PERIOD
    assert not left.exists()


# 5. True messages in every fallback ----------------------------------------------------------
def test_a_missing_newest_checkpoint_is_said_to_be_missing_not_damaged(base, tmp_path):
    out = _copy(base, tmp_path)
    (out / CHECKPOINT_FILE).unlink()
    notices: list[str] = []
    run_trial(out, SETTINGS, resume=True, progress=False, notify=notices.append)
    fallback = [n for n in notices if "previous checkpoint" in n]
    assert len(fallback) == 1 and "is missing" in fallback[0] and "iteration 200" in fallback[0]
    assert "damaged" not in fallback[0] and not (out / DAMAGED_CHECKPOINT_FILE).exists()
    same_state(out, base)


@pytest.mark.parametrize("previous", ["damaged", "missing"])
def test_no_usable_checkpoint_names_both_and_advises_no_resume(base, tmp_path, capsys, previous):
    out = _copy(base, tmp_path)
    _truncate(out / CHECKPOINT_FILE)
    if previous == "damaged":
        _truncate(out / PREVIOUS_CHECKPOINT_FILE)
    else:
        (out / PREVIOUS_CHECKPOINT_FILE).unlink()
    before = _contents(out)
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1 and "--resume" not in err[0]
    assert "cannot be restored" in err[0] and "from scratch" in err[0]
    code, err = _cli(capsys, *_resume_args(out))
    assert code == 2 and len(err) == 1 and "cannot be restored" in err[0]
    assert CHECKPOINT_FILE in err[0] and f"{PREVIOUS_CHECKPOINT_FILE} is {previous}" in err[0]
    with pytest.raises(TrialError, match="cannot be restored"):
        load_trial(out)
    assert _contents(out) == before
