"""A batch's `eval_worlds`: every trial's final agent is also tested in each eval
world; a rerun makes only the evaluations missing or damaged, never runs or evaluates a
complete trial again, and may ask for more worlds."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import pytest

from experiments.batches.runner import eval_world_complete, run_batch
from experiments.batches.spec import BatchError, BatchSpec, load_spec
from experiments.trial_dir import storage
from experiments.trial_dir.layout import COMPETENCE_FILE, EVAL_FILE, LOCK_FILE, eval_world_dir

SPEC = BatchSpec(
    grasps=("kinematic", "physical"),
    seeds=(0,),
    iterations=100,
    checkpoint_every=100,
    eval_placements=1,
    eval_worlds=("physical",),
)
KINEMATIC, PHYSICAL = "kinematic-random-seed0000", "physical-random-seed0000"


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.WARNING)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        Client(cluster) as c,
    ):
        yield c


def _files(out: Path) -> dict[str, bytes]:
    return {
        p.relative_to(out).as_posix(): p.read_bytes()
        for p in sorted(out.rglob("*"))
        if p.is_file() and p.name not in (LOCK_FILE, "batch.json")
    }


def test_a_batch_tests_its_trials_in_its_eval_worlds_and_a_rerun_skips_them(tmp_path, client):
    out = tmp_path / "batch"
    results = run_batch(SPEC, out, client=client, progress=False)
    assert set(results) == {KINEMATIC, PHYSICAL}
    assert set(results[KINEMATIC]["eval_worlds"]) == {"physical"}
    assert results[PHYSICAL]["eval_worlds"] == {}  # the physical world is its own
    tested = storage.read_json(out / KINEMATIC / eval_world_dir("physical") / EVAL_FILE)
    assert tested["eval_world"]["name"] == "physical" and tested["n_placements"] == 1
    assert not (out / PHYSICAL / eval_world_dir("physical")).exists()

    before = _files(out)
    assert run_batch(SPEC, out, client=client, progress=False) == {}
    assert _files(out) == before

    # More worlds asked on a rerun: only what is missing is made, nothing else rewritten.
    both = dataclasses.replace(SPEC, eval_worlds=("kinematic", "physical"))
    results = run_batch(both, out, client=client, progress=False)
    assert set(results) == {PHYSICAL} and set(results[PHYSICAL]["eval_worlds"]) == {"kinematic"}
    made = out / PHYSICAL / eval_world_dir("kinematic")
    assert {k: v for k, v in _files(out).items() if not k.startswith(f"{PHYSICAL}/eval-in-")} == (
        before
    )
    assert storage.read_json(made / EVAL_FILE)["eval_world"]["grasp"] == "kinematic"

    # A damaged table of an evaluation in an eval world: that evaluation alone is made again.
    table = out / KINEMATIC / eval_world_dir("physical") / COMPETENCE_FILE
    table.write_bytes(table.read_bytes()[:100])
    assert not eval_world_complete(out / KINEMATIC, "physical", 1)
    own = (out / KINEMATIC / EVAL_FILE).read_bytes()
    results = run_batch(both, out, client=client, progress=False)
    assert set(results) == {KINEMATIC} and set(results[KINEMATIC]["eval_worlds"]) == {"physical"}
    assert eval_world_complete(out / KINEMATIC, "physical", 1)
    assert (out / KINEMATIC / EVAL_FILE).read_bytes() == own  # its own evaluation kept


def test_eval_worlds_are_checked_where_the_spec_is_read(tmp_path):
    for given, shown in ((["magnetic"], "magnetic"), (["physical", "physical"], "physical")):
        path = tmp_path / "batch.json"
        path.write_text(f'{{"eval_worlds": {given!r}}}'.replace("'", '"'))
        with pytest.raises(BatchError, match=f"eval_worlds must be a list of distinct.*{shown}"):
            load_spec(config_file=path)
    path.write_text('{"eval_worlds": ["kinematic"], "seeds": 1}')
    assert load_spec(config_file=path).eval_worlds == ("kinematic",)
