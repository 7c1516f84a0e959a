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

from experiments import batch as batch_module
from experiments import storage
from experiments.batch import (
    TIMING_FILE,
    BatchError,
    BatchSpec,
    is_complete,
    load_spec,
    run_batch,
)
from experiments.cli import main
from experiments.trial import CHECKPOINT_FILE, read_log


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
    args = [sys.executable, "-m", "experiments.cli", "run", "--grasp", "kinematic"]
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
        running = [a for a, keys in client.processing().items() if target.name in keys]
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
    monkeypatch.setattr(batch_module, "CONNECT_TIMEOUT_S", 1)
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


def test_stored_profiles_hold_what_the_readme_says():
    smoke, demo, paper = (load_spec(p) for p in ("smoke", "demo", "paper"))
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
