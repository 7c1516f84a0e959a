"""Batches refused before anything starts (configs, scheduler addresses), and a batch whose
scheduler goes away: each ends in one line, with nothing written where it should not be."""

from __future__ import annotations

import contextlib
import json
import logging
import os
import socketserver
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

from experiments.batches import runner as batch_module
from experiments.batches import scheduler as scheduler_module
from experiments.batches.runner import run_batch
from experiments.batches.spec import BatchError, BatchSpec, load_spec
from experiments.cli.main import main
from models.checks import MAX_SEED

TINY = BatchSpec(grasps=("kinematic",), seeds=(0,), iterations=10, checkpoint_every=10)


@pytest.mark.parametrize(
    "config, named",
    [
        ({"iterations": 100.9}, "iterations must be a positive integer"),
        ({"iterations": True}, "iterations must be a positive integer"),
        ({"iterations": "100"}, "iterations must be a positive integer"),
        ({"checkpoint_every": 0}, "checkpoint_every must be a positive integer"),
        ({"seeds": [0, 0]}, "seeds must be distinct: [0]"),
        ({"seeds": 1.7}, "seeds must be a positive count"),
        ({"seeds": "two"}, "seeds must be a positive count"),
        ({"seeds": [-1, 2]}, "seeds must be a positive count"),
        ({"seeds": [True]}, "seeds must be a positive count"),
        ({"seeds": 0}, "seeds must be a positive count"),
        ({"seeds": []}, "seeds must be a positive count"),
        ({"seeds": 99999999999999999999999}, "seeds must be a positive count (seeds 0..N-1) up"),
        ({"seeds": 100001}, "seeds must be a positive count (seeds 0..N-1) up to 100000"),
        ({"seeds": [99999999999999999999999]}, "integers in [0, 2**63 - 1], got [99999"),
        ({"seeds": [0, 2**63]}, "integers in [0, 2**63 - 1], got [0, 9223372036854775808]"),
        ({"grasps": []}, "grasps must be a non-empty list of distinct values from kinematic"),
        ({"grasps": "kinematic"}, "grasps must be a non-empty list"),
        ({"grasps": ["kinematic", "kinematic"]}, "grasps must be a non-empty list"),
        ({"grasps": ["kinemtic"]}, "grasps must be a non-empty list"),
        ({"babbling": []}, "babbling must be a non-empty list of distinct values from random"),
        ({"eval_placements": 0}, "eval_placements must be a positive integer"),
        ({"stick_return": "sometimes"}, "stick_return must be one of never, out_of_reach"),
        ({"preset": 1}, "preset must be one of study, project"),
        ({"overrides": []}, "overrides must be an object"),
        ({"overrides": {"sky": {}}}, "overrides must be an object"),
        ({"overrides": {"world": {"no_such_setting": 1}}}, "unknown settings no_such_setting"),
        ({"description": 5}, "description must be a string"),
        ({"study_reference_commands": 0}, "study_reference_commands must be a positive integer"),
        ({"study_reference_commands": 3.5}, "study_reference_commands must be a positive integer"),
        ({"study_reference_commands": "300"}, "study_reference_commands must be a positive"),
        (
            {"base": "nope"},
            "base must be the name of a stored profile (comparison, comparison-diva, demo",
        ),
        ({"base": 1}, "base must be the name of a stored profile"),
        ({"base": "smoke", "iterations": 0}, "iterations must be a positive integer"),
        ({"sede": 3}, "unknown field(s) sede"),
        ([{"seeds": 2}], "must hold a JSON object"),
    ],
)
def test_a_bad_batch_config_is_one_line_and_exit_2_before_anything_starts(
    tmp_path, capsys, config, named
):
    path = tmp_path / "batch.json"
    path.write_text(json.dumps(config))
    out = tmp_path / "out"
    assert main(["batch", "--config", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert named in err, err
    assert not out.exists()


def test_a_good_batch_config_is_taken_as_written(tmp_path):
    path = tmp_path / "batch.json"
    path.write_text(json.dumps({"grasps": ["physical"], "seeds": [7, 3], "iterations": 50}))
    spec = load_spec(config_file=path)
    assert spec.seeds == (7, 3) and spec.grasps == ("physical",) and spec.iterations == 50
    path.write_text(json.dumps({"seeds": 2}))
    assert load_spec(config_file=path).seeds == (0, 1)
    # The largest seed a log's int64 seed column holds (models/checks.py).
    path.write_text(json.dumps({"seeds": [MAX_SEED]}))
    assert load_spec(config_file=path).seeds == (MAX_SEED,) == (2**63 - 1,)


class _Service(socketserver.ThreadingTCPServer):
    """A TCP service on a loopback port that is not a Dask scheduler."""

    daemon_threads = True

    def __init__(self, answer: bytes | None) -> None:
        stop = threading.Event()
        self.stop = stop

        class Handler(socketserver.BaseRequestHandler):
            def handle(self) -> None:
                if answer is not None:
                    self.request.sendall(answer)
                stop.wait(60)  # keeps the connection open, as a service that waits for more

        super().__init__(("127.0.0.1", 0), Handler)
        threading.Thread(target=self.serve_forever, daemon=True).start()

    @property
    def address(self) -> str:
        return f"tcp://127.0.0.1:{self.server_address[1]}"

    def close(self) -> None:
        self.stop.set()
        self.shutdown()
        self.server_close()


@pytest.mark.parametrize(
    "answer, said",
    [
        (b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n", "is not a Dask scheduler"),
        (bytes(range(256)) * 16, "is not a Dask scheduler"),
        (b"SSH", "no Dask scheduler answered"),  # fewer bytes than a frame header: waits
        (None, "no Dask scheduler answered"),  # accepts and says nothing
    ],
    ids=["http", "bytes", "few-bytes", "silent"],
)
def test_a_service_that_is_no_scheduler_ends_the_batch_in_one_line(
    tmp_path, monkeypatch, answer, said
):
    # Loopback answers at once: half a second to connect and half to reply are plenty.
    monkeypatch.setattr(scheduler_module, "CONNECT_TIMEOUT_S", 0.5)
    monkeypatch.setattr(scheduler_module, "REPLY_TIMEOUT_S", 0.5)
    service = _Service(answer)
    pool = ThreadPoolExecutor(1)
    try:
        batch = pool.submit(run_batch, TINY, tmp_path / "out", scheduler=service.address)
        # Bounded by the timeouts above; the bound here only keeps a hang from hanging pytest.
        with pytest.raises(BatchError) as caught:
            batch.result(timeout=60)
    finally:
        service.close()
        pool.shutdown(wait=False)
    message = str(caught.value)
    assert said in message and service.address in message and "\n" not in message
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "address, said",
    [
        ("notaurl", "'notaurl' is not an address (missing port number"),
        ("http://127.0.0.1:8786", "is not an address (unknown address scheme 'http'"),
        ("tcp://127.0.0.1:99999", "is not an address"),
        ("tcp://127.0.0.1:9", "no Dask scheduler answered at tcp://127.0.0.1:9 within 1 s"),
    ],
)
def test_a_bad_scheduler_address_is_one_line_and_exit_2(
    tmp_path, capsys, monkeypatch, address, said
):
    monkeypatch.setattr(scheduler_module, "CONNECT_TIMEOUT_S", 1)
    out = tmp_path / "out"
    code = main(["batch", "--profile", "smoke", "--out", str(out), "--scheduler", address])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and said in err, err
    assert not out.exists()


def test_a_real_scheduler_passes_the_check():
    from distributed import LocalCluster

    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        scheduler_module.check_scheduler(cluster.scheduler_address, timeout_s=5)


# A stand-in for a trial's task that runs until the test lets it go: the scheduler goes away
# while it runs. Module-level, so that Dask pickles it by reference.
_started, _release = threading.Event(), threading.Event()


def _held_task(trial_dir, settings, eval_placements, *reporting) -> dict:
    _started.set()
    _release.wait(60)
    return {}


def test_a_lost_scheduler_ends_the_batch_in_one_line_that_says_how_to_resume(tmp_path, monkeypatch):
    from distributed import Client, LocalCluster

    monkeypatch.setattr(batch_module, "run_and_evaluate", _held_task)
    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    # In this process, so that the stand-in task runs here and is released here.
    cluster = LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    )
    client = Client(cluster, timeout="1s")  # gives up reconnecting after 1 s
    pool = ThreadPoolExecutor(1)
    try:
        batch = pool.submit(run_batch, TINY, tmp_path / "out", client=client, progress=False)
        assert _started.wait(60)
        cluster.sync(cluster.scheduler.close)
        with pytest.raises(BatchError) as caught:
            batch.result(timeout=60)
    finally:
        _release.set()
        pool.shutdown(wait=False)
        client.close()
        for worker in list(cluster.workers.values()):
            cluster.sync(worker.close)
        with contextlib.suppress(TimeoutError):  # its scheduler is gone: nothing to wait for
            cluster.close(timeout=1)
        logging.getLogger("distributed").setLevel(logging.WARNING)
    message = str(caught.value)
    assert "lost the Dask scheduler" in message and "\n" not in message
    assert "run the same command again" in message and "resume from their checkpoints" in message
    assert os.path.isdir(tmp_path / "out")


def test_a_config_on_a_base_profile_changes_only_what_it_names(tmp_path):
    path = tmp_path / "ablation.json"
    path.write_text(
        json.dumps(
            {
                "base": "replication",
                "seeds": 2,
                "overrides": {"learner": {"exploration_sigma": 0.05}},
            }
        )
    )
    spec, base = load_spec(config_file=path), load_spec("replication")
    assert spec.seeds == (0, 1) and spec.overrides == {"learner": {"exploration_sigma": 0.05}}
    assert spec.description == ""  # the base's own words describe the base, not this
    same = ("grasps", "babbling", "iterations", "checkpoint_every", "eval_placements", "preset")
    assert all(getattr(spec, f) == getattr(base, f) for f in same)


def test_batch_set_merges_into_the_specs_overrides_and_is_checked(tmp_path, capsys):
    from experiments.batches.spec import with_overrides
    from experiments.cli.overrides import dotted_setting, merged

    spec = BatchSpec(overrides={"learner": {"exploration_sigma": 0.05}})
    sets = [
        dotted_setting("world.caregiver_bring_rate=0.02"),
        dotted_setting("learner.clip_sensory=false"),
    ]
    changed = with_overrides(spec, merged(spec.overrides, sets))
    assert changed.overrides == {
        "learner": {"exploration_sigma": 0.05, "clip_sensory": False},
        "world": {"caregiver_bring_rate": 0.02},
    }
    assert spec.overrides == {"learner": {"exploration_sigma": 0.05}}  # left as it was
    out = tmp_path / "out"
    args = ["batch", "--profile", "smoke", "--out", str(out)]
    assert main([*args, "--set", "learner.exploration_sigma=-1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("playroom batch: error: --set: ") and "exploration_sigma" in err
    assert len(err.strip().splitlines()) == 1 and not out.exists()
