"""config.json across versions, from the declarations beside the settings' fields: every
setting added since the first one declares what older trials ran with, an older config reads
with those values, and the identities of trials written before stay what they were."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from experiments.run.settings import TrialSettings
from experiments.trial_dir.config_file import (
    added_settings,
    identity_form,
    trial_identity,
    with_added_settings,
)
from sim.config import WorldConfig
from sim.vocal.config import VoiceConfig

DATA = Path(__file__).parents[1] / "data"
# A config.json as `playroom run --seed 7` wrote it at f12e6ee, before the settings declared
# their history beside their fields (experiments/trial_dir/config_file.py held it in a dict then).
WRITTEN = DATA / "config-seed7-written-at-f12e6ee.json"
# The settings of config.json before the first one was added to trials already written (the
# vocal tract, f838cfe): its parent's TrialSettings, WorldConfig and VoiceConfig.
FIRST_SETTINGS = {
    "trial": (
        "grasp",
        "iterations",
        "seed",
        "babbling",
        "checkpoint_every",
        "stick_return",
        "preset",
        "overrides",
    ),
    "world": (
        "segment_lengths",
        "arm_rest_offset",
        "dmp",
        "dmp_weight_scale",
        "stick_length",
        "stick_start_handle",
        "stick_start_angle",
        "toy_replace_period",
        "toy_rings",
        "caregiver_box",
        "grasp_distance",
        "catch_distance",
        "catch_rule",
        "caregiver_bring_rate",
        "stick_return",
    ),
    "voice": (
        "vowels",
        "words",
        "study_vowel_hz",
        "f1_offset",
        "f2_offset",
        "recognition_distance",
        "n_names",
    ),
}
SECTIONS = {"trial": TrialSettings, "world": WorldConfig, "voice": VoiceConfig}
# What every trial written before each added setting ran with (the rules then).
EARLIER = {
    "trial.voice": "vtl",
    "world.voice": "vtl",
    "world.stick_return_reach": None,  # the contact limit
    "world.push_objects": True,
    "world.settle_between_movements": False,
}
# The identities of WRITTEN and of its variants, as f12e6ee computed them: checkpoints and log
# chunks of trials written then carry these, and must stay their own.
IDENTITIES = {
    "as written": "cf18880d0d78",
    "older, without the added settings": "72f1d4627b13",
    "pushing off, settling on, the contact limit": "0ff2f5b372e4",
    "DIVA's voice": "1ad66723e63f",
}


def _written() -> dict:
    return json.loads(WRITTEN.read_text())


def _older() -> dict:
    config = _written()
    for key in EARLIER:
        section, name = key.split(".")
        del config[section][name]
    return config


def _variant(name: str) -> dict:
    config = _written()
    if name == "older, without the added settings":
        return _older()
    if name == "pushing off, settling on, the contact limit":
        config["world"].update(
            push_objects=False, settle_between_movements=True, stick_return_reach=None
        )
    if name == "DIVA's voice":
        config["trial"]["voice"] = config["world"]["voice"] = "diva"
    return config


def test_every_setting_added_since_the_first_declares_what_older_trials_ran_with():
    now = {
        f"{section}.{field.name}"
        for section, cls in SECTIONS.items()
        for field in dataclasses.fields(cls)
    }
    first = {f"{section}.{name}" for section, names in FIRST_SETTINGS.items() for name in names}
    assert set(added_settings()) == now - first  # none missing, none of the first declared
    assert EARLIER.items() <= added_settings().items()  # and those declared before, as before


def test_an_older_config_reads_with_the_values_its_trial_ran_with():
    older = _older()
    filled = with_added_settings(older)
    for key, value in EARLIER.items():
        section, name = key.split(".")
        assert filled[section][name] == value, key
    assert older == _older()  # a copy: the config read is left as it is
    # A config that holds a setting keeps its value, whatever the earlier one.
    written, filled = _written(), with_added_settings(_written())
    for key in added_settings():
        section, name = key.split(".")
        assert filled[section][name] == written[section].get(name, filled[section][name]), key


@pytest.mark.parametrize("variant", IDENTITIES)
def test_the_identities_of_trials_written_before_are_unchanged(variant):
    config = _variant(variant)
    assert trial_identity(config) == {"seed": 7, "config": IDENTITIES[variant]}
    # Filling in the earlier values never changes an identity: they are left out of it.
    assert trial_identity(with_added_settings(config)) == trial_identity(config)


def test_a_setting_at_its_earlier_value_is_left_out_of_the_identity_form():
    form = identity_form(_written())
    assert "voice" not in form["trial"] and "voice" not in form["world"]
    assert form["world"]["stick_return_reach"] == 0.53  # not the earlier value: kept
    assert identity_form(_older()) == _older()
    assert identity_form(with_added_settings(_older())) == _older()
