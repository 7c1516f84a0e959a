"""A comparison says in which rules its two worlds differ besides the grasp backend (the catch
rule, the arm's dynamics, pushing, the held pose...), read from the trials' own configs."""

import json
import re

from experiments.analysis.results import collect
from experiments.measure.for_reports import room_measures
from experiments.report.backend_rules import backend_rules, rules_text
from experiments.report.comparison import write_comparison


def test_each_backends_own_rules_are_named_with_the_values_its_trials_ran(batches):
    configs = {**collect(batches["kinematic"]).configs, **collect(batches["physical"]).configs}
    rules = backend_rules(configs)
    kinematic, physical = configs["kinematic"]["world"], configs["physical"]["world"]
    assert rules["kinematic"]["catch_rule"] == kinematic["catch_rule"]
    assert rules["physical"]["push_objects"] == physical["push_objects"]
    assert "catch_rule" not in rules["physical"] and "push_objects" not in rules["kinematic"]
    text = rules_text(configs)
    assert f"world.catch_rule = {json.dumps(kinematic['catch_rule'])}" in text
    assert f"world.push_objects = {json.dumps(physical['push_objects'])}" in text


def test_the_comparison_page_says_it(batches, tmp_path):
    page = write_comparison(
        batches["kinematic"],
        batches["physical"],
        tmp_path / "cmp",
        grasp_rate_commands=20,
        measures=room_measures(20),
    ).read_text()
    assert re.search(r"differ in more than the grasp rule: kinematic .*world\.catch_rule", page)
    summary = json.loads((tmp_path / "cmp" / "summary.json").read_text())
    assert "catch_rule" in summary["backend_rules"]["kinematic"]
