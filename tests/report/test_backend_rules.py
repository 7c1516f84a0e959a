"""A comparison says in which rules its two worlds differ besides the grasp backend (the catch
rule, the arm's dynamics, pushing, the held pose...), read from the trials' own configs; the
page and summary.json say it (tests/report/test_report.py, the comparison's own test)."""

import json

from experiments.analysis.results import collect
from experiments.report.backend_rules import backend_rules, rules_text


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
