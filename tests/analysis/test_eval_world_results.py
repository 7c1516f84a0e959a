"""A batch's final agents as tested in one eval world, read into the tables of its own
evaluation: each trial's own evaluation where that world is its own, its
eval-in-WORLD/ otherwise, refused in one line when lacking, damaged or of another world."""

from __future__ import annotations

import shutil

import pytest
from bit_flips import flip_number
from old_trials import rewritten_evaluation

from experiments.analysis.eval_world_results import collect
from experiments.analysis.results import ReportError
from experiments.analysis.results import collect as collect_own
from experiments.batches.runner import eval_world_complete
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import COMPETENCE_FILE, CONFIG_FILE, EVAL_FILE, eval_world_dir

ONE = EvaluationSettings(n_placements=1)


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    """A kinematic and a physical trial, each evaluated in its own world, the kinematic one
    also in the physical world."""
    root = tmp_path_factory.mktemp("eval-world-batch")
    for grasp, iterations in (("kinematic", 300), ("physical", 100)):
        trial = root / f"{grasp}-random-seed0000"
        settings = TrialSettings(grasp=grasp, iterations=iterations, checkpoint_every=iterations)
        run_trial(trial, settings, progress=False)
        evaluate_trial(trial, ONE)
    evaluate_trial(root / "kinematic-random-seed0000", ONE, world="physical")
    return root


def test_the_trials_as_tested_in_the_physical_world(batch):
    results = collect(batch, "physical")
    trials = results.trials.set_index("trial")
    kinematic, physical = "kinematic-random-seed0000", "physical-random-seed0000"
    assert trials.loc[kinematic, "grasp"] == "kinematic"  # the backend it learned in
    assert set(trials["tested_grasp"]) == {"physical"} and set(trials["eval_world"]) == {"physical"}
    assert not trials.loc[kinematic, "tested_in_own_world"]
    assert trials.loc[physical, "tested_in_own_world"]
    tested = storage.read_json(batch / kinematic / eval_world_dir("physical") / EVAL_FILE)
    for scope in ("all", "ring1", "ring2", "ring3"):
        assert trials.loc[kinematic, f"competence_{scope}"] == tested["competence"][scope]
    own = collect_own(batch).trials.set_index("trial")
    assert trials.loc[physical, "competence_all"] == own.loc[physical, "competence_all"]
    assert trials.loc[kinematic, "competence_all"] != own.loc[kinematic, "competence_all"]
    # Every test of the evaluation, with its strategy and the words, as for the own world.
    assert len(results.competence) == 2 * 3 * 1 * 3 and set(results.vocal["trial"]) == set(
        trials.index
    )
    assert set(results.competence["strategy"]) <= {"hand", "tool", "vocal"}
    assert collect(batch, "own").trials["competence_all"].tolist() == own["competence_all"].tolist()


def test_trials_lacking_the_evaluation_are_named_with_the_command_that_makes_it(batch):
    with pytest.raises(ReportError) as caught:
        collect(batch, "kinematic")
    message = str(caught.value)
    assert "\n" not in message and "1 of 2 trials" in message
    assert "physical-random-seed0000" in message and "--world kinematic" in message


@pytest.mark.parametrize("damage", ["table", "eval.json", "world"])
def test_a_damaged_or_foreign_evaluation_is_refused_in_one_line(batch, tmp_path, damage):
    copy = shutil.copytree(batch, tmp_path / "batch")
    folder = copy / "kinematic-random-seed0000" / eval_world_dir("physical")
    if damage == "table":
        data = bytearray((folder / COMPETENCE_FILE).read_bytes())
        data[len(data) // 2] ^= 0xFF
        (folder / COMPETENCE_FILE).write_bytes(bytes(data))
    elif damage == "eval.json":  # still JSON, another number
        ring1 = storage.read_json(folder / EVAL_FILE)["competence"]["ring1"]
        flip_number(folder / EVAL_FILE, "ring1", ring1)
    else:  # made for another declaration of the world than today's
        config = storage.read_json(folder.parent / CONFIG_FILE)
        rewritten_evaluation(folder, config, _declared_without_pushing)
    with pytest.raises(ReportError) as caught:
        collect(copy, "physical")
    message = str(caught.value)
    assert "\n" not in message and str(folder) in message and "--world physical" in message
    said = {"table": f"{COMPETENCE_FILE} is damaged", "eval.json": f"{EVAL_FILE} is damaged"}
    assert said.get(damage, "as declared now") in message
    assert not eval_world_complete(folder.parent, "physical", 1)  # a batch rerun makes it again


def test_an_unknown_world_is_refused():
    with pytest.raises(ReportError, match="unknown eval world 'magnetic'"):
        collect(".", "magnetic")


def test_a_world_setting_added_since_does_not_make_an_evaluation_stale(batch, tmp_path):
    copy = shutil.copytree(batch, tmp_path / "batch")
    trial = copy / "kinematic-random-seed0000"
    config = storage.read_json(trial / CONFIG_FILE)
    # As if written before the setting existed.
    rewritten_evaluation(trial / eval_world_dir("physical"), config, _without_voice)
    assert len(collect(copy, "physical").trials) == 2


def _declared_without_pushing(summary: dict) -> None:
    summary["eval_world"]["world"]["push_objects"] = False


def _without_voice(summary: dict) -> None:
    del summary["eval_world"]["world"]["voice"]


def test_the_cross_world_table_reads_each_trial_as_each_world_tested_it(batch, tmp_path):
    from experiments.analysis.cross_worlds import MissingTestError, cross_table

    table = cross_table({"both": batch}, ("physical",))
    where = table.set_index("trial")["evaluation"].to_dict()
    assert where == {"kinematic-random-seed0000": "cross", "physical-random-seed0000": "own"}
    with pytest.raises(MissingTestError, match="--world kinematic"):
        cross_table({"both": batch}, ("kinematic",))  # the physical trial was not tested there
    copy = shutil.copytree(batch, tmp_path / "damaged")
    table_path = copy / "kinematic-random-seed0000" / eval_world_dir("physical") / COMPETENCE_FILE
    storage.write_table(table_path, storage.read_table(table_path).iloc[:-1])
    with pytest.raises(storage.CorruptFileError, match=COMPETENCE_FILE):
        cross_table({"both": copy}, ("physical",))
