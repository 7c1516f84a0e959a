"""Batches on Dask: the smoke profile on a LocalCluster, resume, a killed worker, bad input."""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from experiments.analysis.logs import read_log
from experiments.batches import scheduler as scheduler_module
from experiments.batches.runner import is_complete, run_batch
from experiments.batches.spec import BatchError, BatchSpec, load_spec
from experiments.cli.main import main
from experiments.trial_dir import eval_record, storage
from experiments.trial_dir.layout import CHECKPOINT_FILE, TIMING_FILE


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.WARNING)
    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    with Client(cluster) as c:
        yield c
    cluster.close()


def _wait_for(path: Path, polls: int = 2400) -> None:
    """Poll (every 50 ms, at most `polls` times) until `path` exists; no clock is read."""
    for _ in range(polls):
        if path.exists():
            return
        time.sleep(0.05)


def _wait_for_first_checkpoint(trial_dir: Path, polls: int = 2400) -> None:
    """Poll (every 50 ms, at most `polls` times) until the trial has a checkpoint past
    iteration 0 (a run writes one at 0 before it starts); no clock is read."""
    for _ in range(polls):
        try:
            if storage.read_arrays(trial_dir / CHECKPOINT_FILE)[1]["iteration"] > 0:
                return
        except (FileNotFoundError, storage.CorruptFileError):
            pass
        time.sleep(0.05)


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_smoke_profile_runs_on_a_local_cluster_with_two_workers(tmp_path, client):
    spec = load_spec("smoke")
    assert len(client.scheduler_info()["workers"]) == 2
    results = run_batch(spec, tmp_path, client=client, progress=False)
    assert sorted(results) == sorted(name for name, _ in spec.trials())
    for name, settings in spec.trials():
        assert is_complete(tmp_path / name)
        assert len(read_log(tmp_path / name)) == settings.iterations
    # Rerunning skips every complete trial.
    assert run_batch(spec, tmp_path, client=client, progress=False) == {}


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_rerun_resumes_an_unfinished_trial_from_its_checkpoint(tmp_path, client):
    spec = BatchSpec(
        grasps=("kinematic",),
        seeds=(0,),
        iterations=1500,
        checkpoint_every=100,
        eval_placements=2,
    )
    name, settings = spec.trials()[0]
    trial_dir = tmp_path / name
    # An interrupted batch: the trial's process is killed after its first checkpoint.
    args = [sys.executable, "-m", "experiments.cli.main", "run", "--grasp", "kinematic"]
    args += ["--iterations", "1500", "--seed", "0", "--checkpoint-every", "100", "--quiet"]
    proc = subprocess.Popen([*args, "--out", str(trial_dir)])
    _wait_for_first_checkpoint(trial_dir)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not is_complete(trial_dir)
    results = run_batch(spec, tmp_path, client=client, progress=False)
    assert name in results and is_complete(trial_dir)
    assert list(read_log(trial_dir)["iteration"]) == list(range(1500))
    # Only the iterations after the checkpoint were run again.
    timing = storage.read_json(trial_dir / TIMING_FILE)
    assert 0 < timing["iterations"] < 1500


@pytest.mark.slow  # 12 s: in make test-slow, to keep make test's pytest under 2 minutes
def test_a_killed_worker_has_its_trial_retried_without_duplicates(tmp_path, client):
    spec = BatchSpec(
        grasps=("kinematic",),
        seeds=(0, 1),
        iterations=1500,
        checkpoint_every=250,
        eval_placements=2,
    )
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        batch = pool.submit(run_batch, spec, tmp_path, client=client, progress=False)
        # Wait until a trial has checkpointed, then kill the worker running it.
        target = tmp_path / spec.trials()[0][0]
        _wait_for_first_checkpoint(target)
        pids = client.run(os.getpid)
        running = [
            a
            for a, keys in client.processing().items()
            if any(k.startswith(f"{target.name}-") for k in keys)  # keys: name-digest-run
        ]
        assert len(running) == 1, client.processing()
        os.kill(pids[running[0]], signal.SIGKILL)
        results = batch.result(timeout=300)
    assert len(results) == 2
    for name, settings in spec.trials():
        log = read_log(tmp_path / name)
        assert list(log["iteration"]) == list(range(settings.iterations)), name
        assert is_complete(tmp_path / name)
    # The retry resumed the killed trial from its checkpoint.
    timing = storage.read_json(target / TIMING_FILE)
    assert 0 < timing["iterations"] < spec.iterations


def test_bad_batch_input_is_a_one_line_error(tmp_path, capsys, monkeypatch):
    # Nothing listens on port 9: a short wait for the scheduler is enough to give up.
    monkeypatch.setattr(scheduler_module, "CONNECT_TIMEOUT_S", 1)
    with pytest.raises(BatchError, match="unknown profile"):
        load_spec("huge")
    bad = tmp_path / "bad.json"
    bad.write_text('{"seeds": 2, "iterations": 0}')
    with pytest.raises(BatchError, match="iterations"):
        load_spec(config_file=bad)
    code = main(
        [
            "batch",
            "--profile",
            "smoke",
            "--out",
            str(tmp_path / "b"),
            "--scheduler",
            "tcp://127.0.0.1:9",
        ]
    )
    assert code == 2
    err = capsys.readouterr().err
    assert "no Dask scheduler answered" in err and len(err.strip().splitlines()) == 1
    assert not any(Path(tmp_path / "b").glob("*/config.json"))


def _tiny(preset: str = "study", seeds: tuple[int, ...] = (0,)) -> BatchSpec:
    return BatchSpec(
        grasps=("kinematic",), seeds=seeds, iterations=100, checkpoint_every=100,
        eval_placements=1, preset=preset,
    )  # fmt: skip


def test_two_batches_with_the_same_trial_names_on_one_scheduler_stay_apart(tmp_path, client):
    from concurrent.futures import ThreadPoolExecutor

    from distributed import Client

    study, project = _tiny("study"), _tiny("project")
    name = study.trials()[0][0]
    assert name == project.trials()[0][0]
    # Two users' clients of one scheduler, the second submitting while the first one's trial
    # of the same name runs.
    with Client(client.scheduler.address) as other, ThreadPoolExecutor(1) as pool:
        first = pool.submit(run_batch, study, tmp_path / "a", client=client, progress=False)
        _wait_for(tmp_path / "a" / name / "config.json")
        second = run_batch(project, tmp_path / "b", client=other, progress=False)
        first = first.result(timeout=300)
    for batch, spec, results in (("a", study, first), ("b", project, second)):
        trial = tmp_path / batch / name
        assert is_complete(trial), batch
        assert storage.read_json(trial / "config.json")["trial"]["preset"] == spec.preset
        config = storage.read_json(trial / "config.json")
        written = eval_record.read_evaluation(trial, config, "")  # as every reader reads it
        assert results[name] == {**written, "wall_seconds": results[name]["wall_seconds"]}


def test_a_relative_out_is_where_the_client_runs_not_where_the_workers_do(
    tmp_path, client, monkeypatch
):
    here, elsewhere = tmp_path / "client", tmp_path / "worker"
    here.mkdir()
    elsewhere.mkdir()
    monkeypatch.chdir(here)
    before = client.run(os.getcwd)
    client.run(os.chdir, str(elsewhere))
    try:
        results = run_batch(_tiny(), "batch", client=client, progress=False)
    finally:
        for address, cwd in before.items():
            client.run(os.chdir, cwd, workers=[address])
    name = _tiny().trials()[0][0]
    assert list(results) == [name] and is_complete(here / "batch" / name)
    assert not (elsewhere / "batch").exists()


_HOLD = """import fcntl, os, sys
fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT)
fcntl.flock(fd, fcntl.LOCK_EX)
os.pwrite(fd, f"{os.getpid()}\\n".encode(), 0)
print("held", flush=True)
sys.stdin.read()
"""


def test_a_batch_says_when_a_trial_waits_for_another_writer(tmp_path, client):
    from concurrent.futures import ThreadPoolExecutor

    spec = _tiny()
    trial = tmp_path / spec.trials()[0][0]
    trial.mkdir()
    # Another process writes the trial (its lock taken as experiments/trial_dir/lock.py takes it).
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLD, str(trial / ".lock")],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    said: list[str] = []
    try:
        assert holder.stdout.readline() == "held\n"
        with ThreadPoolExecutor(1) as pool:
            batch = pool.submit(
                run_batch, spec, tmp_path, client=client, progress=False, notify=said.append
            )
            for _ in range(1200):  # the task tells it before it waits (at most 60 s here)
                if said:
                    break
                time.sleep(0.05)
            assert not batch.done()
            holder.stdin.close()  # the other writer ends: the batch goes on
            holder.wait()
            results = batch.result(timeout=300)
    finally:
        holder.kill()
        holder.wait()
    assert len(said) == 1, said
    assert f"pid {holder.pid}" in said[0] and str(trial) in said[0] and "4 h" in said[0]
    assert list(results) == [trial.name] and is_complete(trial)


def test_stored_profiles_hold_what_the_readme_says(installed_generated_map):
    smoke, demo, paper = (load_spec(p) for p in ("smoke", "demo", "paper"))
    # The study reference of their reports: the study's own at its scale, smaller for batches
    # of short trials (experiments/batches/profiles/ says which).
    assert (smoke.study_reference_commands, demo.study_reference_commands) == (300, 3000)
    for name in ("paper", "replication", "comparison", "replication-diva"):
        assert load_spec(name).study_reference_commands == 30000, name
    assert len(smoke.trials()) == 4 and smoke.iterations <= 500
    assert set(demo.grasps) == {"kinematic", "physical"} and len(demo.trials()) == 8
    assert demo.iterations == 20000
    assert len(paper.seeds) == 500 and paper.iterations == 80000 and len(paper.trials()) == 1000
    assert paper.eval_placements == 100
    replication = load_spec("replication")
    assert replication.grasps == ("kinematic",) and len(replication.seeds) == 100
    assert replication.iterations == 80000 and replication.preset == "study"
    assert all(s.preset == "study" for _, s in replication.trials())
    comparison = load_spec("comparison")
    assert set(comparison.grasps) == {"kinematic", "physical"} and len(comparison.seeds) == 16
    assert comparison.iterations == 80000 and comparison.eval_placements == 100
    assert all(s.preset == "study" for _, s in comparison.trials())
