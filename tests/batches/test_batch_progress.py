"""What a batch shows while it runs: the Dask dashboard's link (served, for a local cluster and
for a scheduler given by address), a bar that advances within trials and names those running,
and batch.json, which records what the batch is (its reports' reference size)."""

from __future__ import annotations

import logging
import threading
import urllib.request

import pytest

from experiments.analysis.batch_record import recorded_reference_commands
from experiments.batch_files import BATCH_FILE
from experiments.batches import progress as progress_module
from experiments.batches import scheduler as dask_scheduler
from experiments.batches.runner import run_batch
from experiments.batches.spec import BatchSpec
from experiments.trial_dir import storage

TINY = BatchSpec(
    grasps=("kinematic",),
    seeds=(0, 1),
    iterations=20,
    checkpoint_every=20,
    eval_placements=1,
    study_reference_commands=30,
)


def _served(link: str) -> int:
    with urllib.request.urlopen(link, timeout=30) as response:
        return response.status


@pytest.fixture(scope="module")
def cluster():
    """A local cluster as `playroom batch` makes one (its dashboard on a free port)."""
    client, own = dask_scheduler.connect(None, 1)
    yield client, own
    client.close()
    own.close()
    logging.getLogger("distributed").setLevel(logging.WARNING)


def test_a_local_cluster_serves_its_dashboard(cluster):
    client, _ = cluster
    link = progress_module.dashboard_link(client)
    assert link is not None and link.startswith("http://") and link.endswith("/status")
    assert _served(link) == 200  # not distributed's 404 page of a dashboard without bokeh


def test_a_batch_prints_the_link_and_advances_within_each_trial(
    tmp_path, cluster, capsys, monkeypatch
):
    client, own = cluster
    seen: list[tuple[str, int, list[str]]] = []
    original = progress_module.BatchProgress.reached

    def recording(self, name: str, iteration: int, *where) -> None:
        original(self, name, iteration, *where)
        seen.append((name, iteration, self.running()))

    monkeypatch.setattr(progress_module.BatchProgress, "reached", recording)
    # Through the scheduler's address, as `--scheduler tcp://...` connects.
    results = run_batch(
        TINY,
        tmp_path,
        scheduler=own.scheduler_address,
        progress=True,
        report_every=5,
        report_interval_s=0.0,
    )
    assert sorted(results) == [name for name, _ in TINY.trials()]
    err = capsys.readouterr().err
    link_lines = [line for line in err.splitlines() if "Dask dashboard: " in line]
    assert len(link_lines) == 1, err
    link = link_lines[0].split("Dask dashboard: ")[1].strip()
    assert link == own.dashboard_link and _served(link) == 200
    for name, _ in TINY.trials():
        reached = [iteration for trial, iteration, _ in seen if trial == name]
        # Reported as it ran, not only at its end: 0 (its start), 5, 10, 15, 20.
        assert reached == [0, 5, 10, 15, 20], seen
        assert all(name in running for trial, _, running in seen if trial == name)
    assert "40/40" in err  # the bar counts iterations across the trials
    assert storage.read_json(tmp_path / BATCH_FILE)["study_reference_commands"] == 30
    assert recorded_reference_commands([tmp_path]) == 30


def test_the_bar_names_running_trials_and_counts_the_rest():
    shown = progress_module.BatchProgress({f"t{k}": 10 for k in range(5)}, enabled=False)
    for k in range(5):
        shown.reached(f"t{k}", 4)
    shown.ended("t0", failed=False)
    shown.ended("t1", failed=True)
    assert shown.running() == ["t2", "t3", "t4"]
    assert shown.iterations_done() == 10 + 4 * 4  # t0 counted whole once done
    shown.reached("t2", 99)  # never past a trial's own length
    assert shown.iterations_done() == 10 + 4 * 4 + 6
    assert "running 3: t2, t3, t4" in shown.postfix()
    shown.close()


def test_the_bar_counts_one_trial_per_task_thread_and_none_after_its_end():
    shown = progress_module.BatchProgress({"a": 10, "b": 10, "c": 10}, enabled=False)
    shown.reached("a", 0, "worker1/7")
    shown.reached("b", 0, "worker2/7")
    shown.reached("c", 0, "worker1/7")  # worker1's next trial, before a's end was seen
    assert shown.running() == ["b", "c"]  # 2 threads: never 3 running
    shown.ended("a", failed=False)
    shown.reached("a", 5, "worker1/7")  # a's last report, arriving after its end
    assert shown.running() == ["b", "c"] and shown.iterations_done() == 10
    shown.ended("c", failed=False)
    shown.ended("b", failed=True)
    assert shown.running() == [] and "done 2, failed 1, running 0" in shown.postfix()
    shown.close()


def test_the_largest_recorded_size_applies_and_none_without_a_record(tmp_path):
    small, large, old = tmp_path / "small", tmp_path / "large", tmp_path / "old"
    for path, size in ((small, 300), (large, 30000)):
        path.mkdir()
        storage.write_json(path / BATCH_FILE, {"study_reference_commands": size})
    old.mkdir()
    assert recorded_reference_commands([small]) == 300
    assert recorded_reference_commands([small, large, old]) == 30000
    assert recorded_reference_commands([old]) is None


def test_a_local_cluster_s_workers_wake_seldom(cluster):
    """Dask's default 20 ms ticks and 10 ms stack samples slowed trials by a tenth."""
    import dask

    client, _ = cluster
    keys = sorted(dask_scheduler.LOCAL_WORKER_CONFIG)
    seen = client.run(lambda: [dask.config.get(key) for key in keys])
    for values in seen.values():
        assert values == [dask_scheduler.LOCAL_WORKER_CONFIG[key] for key in keys]


def test_a_trial_reports_its_start_then_at_most_once_a_while(monkeypatch):
    import distributed

    sent: list[dict] = []

    class Worker:
        address = "tcp://worker"

        def log_event(self, topic: str, message: dict) -> None:
            sent.append(message)

    monkeypatch.setattr(distributed, "get_worker", Worker)
    seldom = progress_module.reporter("topic", "trial", min_interval_s=3600.0)
    assert seldom is not None
    for iteration in (0, 100, 200):
        seldom(iteration)
    here = f"tcp://worker/{threading.get_ident()}"  # the task thread that runs the trial
    assert sent == [{"trial": "trial", "iteration": 0, "thread": here}]
    every_time = progress_module.reporter("topic", "trial", min_interval_s=0.0)
    assert every_time is not None
    every_time(300)
    assert sent[-1] == {"trial": "trial", "iteration": 300, "thread": here}
