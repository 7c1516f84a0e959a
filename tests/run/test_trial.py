"""One trial (`playroom run`): learning, checkpoints, kill and resume, bad input."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from trial_states import same_state

from experiments.analysis.logs import read_log
from experiments.cli.main import main
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CHECKPOINT_FILE
from models.layout import SAMPLE_INDICES
from sim import Playroom
from sim.config import world_preset
from sim.dmp import arm_trajectory
from sim.kinematics import hand_positions

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")

PLAYROOM = [sys.executable, "-m", "experiments.cli.main"]
REPO = Path(__file__).resolve().parents[2]


def _run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*PLAYROOM, *args], capture_output=True, text=True, cwd=REPO)


def _arrays_equal(a: dict, b: dict) -> None:
    assert sorted(a) == sorted(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_run_writes_config_checkpoint_and_logs(tmp_path, grasp):
    out = tmp_path / "trial"
    trial = run_trial(
        out, TrialSettings(grasp=grasp, iterations=120, seed=1, checkpoint_every=50), progress=False
    )
    assert trial.iteration == 120
    config = storage.read_json(out / "config.json")
    assert config["trial"]["seed"] == 1 and config["trial"]["grasp"] == grasp
    # The default preset is the study's code: its sigma, its DMP, its catch rule.
    assert "package_version" in config and config["learner"]["exploration_sigma"] == 0.1
    assert config["world"]["dmp"] == "study" and config["world"]["catch_rule"] == "study"
    log = read_log(out)
    assert list(log["iteration"]) == list(range(120))
    assert set(log["motor_space"]) <= {"arm", "voice"}
    words = read_log(out, "words")
    assert list(words["iteration"]) == [100]
    arrays, meta = storage.read_arrays(out / CHECKPOINT_FILE)
    assert meta["iteration"] == 120 and meta["finished"]


def _checkpointed_iteration(trial_dir: Path) -> int:
    """The iteration of the trial's newest readable checkpoint (0 if none yet)."""
    try:
        return storage.read_arrays(trial_dir / CHECKPOINT_FILE)[1]["iteration"]
    except (FileNotFoundError, storage.CorruptFileError):
        return 0


@pytest.mark.slow  # over 5 s: make test-slow runs it
# The project preset's memory grows from the first iteration, each period's rows in a memory
# segment (the study's stores nothing before iteration 1000).
@pytest.mark.parametrize(
    "grasp, seed, preset",
    [("kinematic", 4, "study"), ("physical", 5, "study"), ("kinematic", 6, "project")],
)
def test_killed_run_resumes_to_the_same_memory_and_logs(tmp_path, grasp, seed, preset):
    total, period = 1500, 100
    args = ["run", "--grasp", grasp, "--iterations", str(total), "--seed", "4"]
    args += ["--checkpoint-every", str(period), "--preset", preset, "--quiet"]
    whole = tmp_path / "whole"
    assert _run_cli(*args, "--out", str(whole)).returncode == 0

    killed = tmp_path / "killed"
    proc = subprocess.Popen([*PLAYROOM, *args, "--out", str(killed)], cwd=REPO)
    # Killed at a seeded moment: once a seeded checkpoint is on disk, before the next one.
    kill_after = int(np.random.default_rng(seed).integers(1, 6)) * period
    while _checkpointed_iteration(killed) < kill_after and proc.poll() is None:
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    interrupted_at = _checkpointed_iteration(killed)
    assert kill_after <= interrupted_at < total, "the kill did not cut the run short"
    resumed = _run_cli(*args, "--out", str(killed), "--resume")
    assert resumed.returncode == 0, resumed.stderr

    same_state(whole, killed)


def test_a_3000_iteration_run_learns_to_reach_hand_goals(trained_trial):
    """After 3000 kinematic iterations the hand model reaches random reachable hand goals better
    than an agent that acts at random."""
    trial = trained_trial
    agent = trial.agent
    rng = np.random.default_rng(123)
    room = Playroom("kinematic", seed=77, config=PROJECT)
    learned, random_errors = [], []
    for _ in range(60):
        # A reachable goal: the hand trajectory of another random command, at the 5 samples.
        joints = arm_trajectory(rng.uniform(-1, 1, 21))[:, list(SAMPLE_INDICES)]
        target = hand_positions(joints)  # (5, 2)
        goal = np.concatenate([target[:, 0], target[:, 1]])
        context = room.context()
        m = agent.exploit(0, context, goal)
        learned.append(np.linalg.norm(room.act_arm(m).s[0:10] - goal))
        random_errors.append(np.linalg.norm(room.act_arm(rng.uniform(-1, 1, 21)).s[0:10] - goal))
    assert np.mean(learned) < 0.7 * np.mean(random_errors)


# Bad input ----------------------------------------------------------------------------------
@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_directory_with_a_trial_is_refused_without_resume(tmp_path):
    out = tmp_path / "t"
    args = ["run", "--iterations", "20", "--seed", "0", "--out", str(out), "--quiet"]
    assert _run_cli(*args).returncode == 0
    before = storage.read_arrays(out / CHECKPOINT_FILE)[0]
    again = _run_cli(*args)
    assert again.returncode == 2 and "already holds a trial" in again.stderr
    assert len(again.stderr.strip().splitlines()) == 1
    other = _run_cli("run", "--iterations", "20", "--seed", "5", "--out", str(out), "--resume")
    assert other.returncode == 2 and "another configuration" in other.stderr
    _arrays_equal(before, storage.read_arrays(out / CHECKPOINT_FILE)[0])


def test_bad_arguments_exit_2_with_argparses_usage_or_one_line(tmp_path, capsys):
    a_file = tmp_path / "file"
    a_file.write_text("x")
    # argparse's own errors: the command's usage line, then the error.
    parsing = [
        ["run", "--out", str(tmp_path / "a"), "--iterations", "0"],
        ["run", "--out", str(tmp_path / "a"), "--iterations", "-5"],
        ["run", "--out", str(tmp_path / "a"), "--grasp", "magnetic"],
        ["run", "--out", str(tmp_path / "a"), "--frobnicate"],
    ]
    for argv in parsing:
        assert main(argv) == 2, argv
        lines = capsys.readouterr().err.strip().splitlines()
        assert lines[0].startswith("usage: playroom run "), lines
        assert lines[-1].startswith("playroom run: error: "), lines
    # The command's own refusals: one line.
    assert main(["run", "--out", str(a_file), "--iterations", "5"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert a_file.read_text() == "x"


def test_unwritable_directory_is_refused(tmp_path):
    # /proc refuses new directories even to root; a read-only folder refuses other users.
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    target = "/proc/playroom-trial" if os.geteuid() == 0 else str(locked / "t")
    result = _run_cli("run", "--iterations", "5", "--out", target)
    assert result.returncode == 2 and "cannot write" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_agent_is_the_learner_package():
    # The trial wires sim and learner; learner itself must not import MuJoCo or sim.
    code = (
        "import sys, learner.agent; "
        "print(any(m.split('.')[0] in ('mujoco', 'sim', 'dm_control') for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "False"
