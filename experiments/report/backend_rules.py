"""In which rules two groups' worlds differ besides their grasp backend: each backend reads
settings the other does not (experiments/trial_dir/eval_worlds.py READ_BY, from the world's fields'
ACTS_ON), and a difference between the groups is the sum of all of them, not of the grasp
rule alone. Read from the trials' own config.json, so that the page cannot name a rule its
trials did not run."""

from __future__ import annotations

import json

from experiments.report.ablations import describe_change
from experiments.trial_dir.eval_worlds import READ_BY

# What describe_change says of two configs that do not differ.
NO_CHANGE = "the baseline's settings"


def backend_rules(configs: dict[str, dict]) -> dict[str, dict[str, object]]:
    """Per group: the world settings only its backend reads, with the values its trials ran."""
    out = {}
    for group, config in configs.items():
        grasp = config["trial"]["grasp"]
        world = config["world"]
        out[group] = {name: world.get(name) for name in READ_BY.get(grasp, ()) if name in world}
    return out


def rules_text(configs: dict[str, dict]) -> str:
    """One paragraph: each group's backend-only rules and the settings both read that differ."""
    if len(configs) != 2:
        return ""
    rules = backend_rules(configs)
    parts = []
    for group, settings in rules.items():
        grasp = configs[group]["trial"]["grasp"]
        named = ", ".join(f"world.{k} = {json.dumps(v)}" for k, v in settings.items()) or "none"
        parts.append(f"{group} ({grasp} backend) also runs under {named}")
    (_, first), (_, second) = configs.items()
    switches = {name for names in READ_BY.values() for name in names}
    shared = [
        change
        for change in describe_change(first, second).split("; ")
        if change.split(":")[0] != "trial.grasp"
        and change.split(":")[0].removeprefix("world.") not in switches
        and change != NO_CHANGE
    ]
    common = "they also differ in " + "; ".join(shared) if shared else "all else is the same"
    return (
        f"The two worlds differ in more than the grasp rule: {'; '.join(parts)} (settings the "
        f"other backend does not read; docs/world.md); {common}. A difference below is the "
        "sum of all of these: `playroom ladder` attributes it rule by rule."
    )
