"""Every setting is checked where its config is built, before a trial writes anything; a
resumed trial runs with the settings in its config.json."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from experiments.analysis.logs import read_log
from experiments.analysis.trial_rows import eval_numbers
from experiments.cli.main import main
from experiments.run.settings import TrialSettings, resume_settings
from experiments.run.trial import run_trial
from experiments.run.trial_config import full_config
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import identity_form, with_added_settings
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import CHECKPOINT_FILE, CONFIG_FILE
from learner.config import LearnerConfig
from sim.config import DEFAULT_WORLD, WorldConfig, config_from_dict, world_preset
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

NAN, INF = float("nan"), float("inf")
# The bounds the messages name: distances within the room, periods within an int64, noise within
# the motor range.
ROOM = r"\(0, 3.7\]"
PERIODS = r"\[1, 2\*\*63 - 1\]"
SIGMA = r"\[0, 2.0\]"

# (world setting, value, what the message must say): the examples, and their kin.
BAD_WORLD = [
    ("catch_rule", "held_stik", "catch_rule must be one of 'study', 'held_stick'"),
    ("catch_rule", "Study", "catch_rule must be one of 'study', 'held_stick'"),
    ("dmp", "studdy", "dmp must be one of 'study', 'project'"),
    ("stick_return", "sometimes", "stick_return must be one of 'never', 'out_of_reach'"),
    ("grasp_distance", NAN, rf"grasp_distance must be a finite number in {ROOM}, got nan"),
    ("grasp_distance", INF, rf"grasp_distance must be a finite number in {ROOM}, got inf"),
    ("grasp_distance", -1, rf"grasp_distance must be a finite number in {ROOM}, got -1"),
    ("grasp_distance", "0.1", rf"grasp_distance must be a finite number in {ROOM}, got '0.1'"),
    ("catch_distance", True, rf"catch_distance must be a finite number in {ROOM}, got True"),
    ("caregiver_bring_rate", 0.0, r"caregiver_bring_rate must be a finite number in \(0, 1\]"),
    ("caregiver_bring_rate", 1.5, r"caregiver_bring_rate must be a finite number in \(0, 1\]"),
    ("toy_replace_period", 0, rf"toy_replace_period must be an integer in {PERIODS}, got 0"),
    ("toy_replace_period", 20.0, rf"toy_replace_period must be an integer in {PERIODS}, got 20.0"),
    ("toy_replace_period", True, rf"toy_replace_period must be an integer in {PERIODS}, got True"),
    ("segment_lengths", [0.25, 0.15], rf"segment_lengths must be 3 finite numbers in {ROOM}"),
    ("segment_lengths", [0.25, 0.15, -0.1], rf"segment_lengths must be 3 finite numbers in {ROOM}"),
    (
        "stick_start_handle",
        [-0.25, NAN],
        r"stick_start_handle must be 2 finite numbers in \[-1.3, 1.3\]",
    ),
    ("toy_rings", [[0, 0.5], [0.5, 0.75]], "toy_rings must be 3 .low, high. pairs"),
    ("toy_rings", [[0, 0.5], [0.75, 0.5], [0.75, 1]], "toy_rings must be 3 .low, high. pairs"),
    ("dmp_weight_scale", 0, r"dmp_weight_scale must be a finite number in \(0, 30000\]"),
    # None (the contact limit) or a distance: never 0, a string or not finite.
    ("stick_return_reach", 0, rf"stick_return_reach must be a finite number in {ROOM}, got 0"),
    (
        "stick_return_reach",
        "0.53",
        rf"stick_return_reach must be a finite number in {ROOM}, got '0.53'",
    ),
    ("stick_return_reach", INF, rf"stick_return_reach must be a finite number in {ROOM}, got inf"),
    # No upper bounds before: each of these ran to its end.
    ("grasp_distance", 1e308, rf"grasp_distance must be a finite number in {ROOM}, got 1e\+308"),
    ("catch_distance", 4.0, rf"catch_distance must be a finite number in {ROOM}, got 4.0"),
    ("dmp_weight_scale", 1e308, r"dmp_weight_scale must be a finite number in \(0, 30000\]"),
    ("toy_replace_period", 99999999999999999999999, rf"toy_replace_period must be .* in {PERIODS}"),
    ("caregiver_box", 2.0, r"caregiver_box must be a finite number in \(0, 1.3\], got 2.0"),
    ("stick_start_handle", [-0.25, 1e308], r"stick_start_handle must be 2 finite numbers in"),
    ("toy_rings", [[0, 0.5], [0.5, 0.75], [0.75, 1e308]], r"toy_rings .* high <= 3.7"),
    ("stick_return_reach", 1e308, rf"stick_return_reach must be a finite number in {ROOM}"),
]

BAD_LEARNER = [
    ("babbling", "Random", "babbling must be one of 'random', 'active'"),
    ("storing_rule", "moved", "storing_rule must be one of"),
    ("clip_sensory", 1, "clip_sensory must be true or false, got 1"),
    ("clip_sensory", "false", "clip_sensory must be true or false"),
    (
        "exploration_sigma",
        "0.1",
        rf"exploration_sigma must be a finite number in {SIGMA}, got '0.1'",
    ),
    ("exploration_sigma", INF, rf"exploration_sigma must be a finite number in {SIGMA}, got inf"),
    ("imitation_share", NAN, r"imitation_share must be a finite number in \[0, 1\]"),
    ("outcomes_to_infer", 2.0, rf"outcomes_to_infer must be an integer in {PERIODS}, got 2.0"),
    ("bootstrap_arm", True, r"bootstrap_arm must be an integer in \[0, 10000000\], got True"),
    ("motor_high", NAN, r"motor_high must be a finite number in \[-1, 1\], got nan"),
    ("exploration_sigma", 1e308, rf"exploration_sigma must be a finite number in {SIGMA}, got 1e"),
    ("progress_window", 100000000000, r"progress_window must be an integer in \[1, 1000000\]"),
    ("progress_window", 99999999999999999999, r"progress_window must be an integer in \[1, 10"),
    ("imitation_memory", 10**9, r"imitation_memory must be an integer in \[1, 1000000\]"),
    ("bootstrap_voice", 10**12, r"bootstrap_voice must be an integer in \[0, 10000000\]"),
    ("outcomes_to_infer", 2**63, rf"outcomes_to_infer must be an integer in {PERIODS}"),
    ("motor_low", -2.0, r"motor_low must be a finite number in \[-1, 1\], got -2.0"),
    ("goal_high", 1e308, r"goal_high must be a finite number in \[-2, 2\], got 1e\+308"),
    ("change_tolerance", 1e308, r"change_tolerance must be a finite number in \[0, 4\]"),
]


def _one_line(message: str) -> None:
    assert "\n" not in message.strip(), message


@pytest.mark.parametrize(("name", "value", "says"), BAD_WORLD)
def test_a_bad_world_setting_is_refused_where_the_config_is_built(name, value, says):
    with pytest.raises(ValueError, match=f"WorldConfig.{says}") as exc:
        dataclasses.replace(DEFAULT_WORLD, **{name: value})
    _one_line(str(exc.value))
    with pytest.raises(ValueError, match=says):  # and as read back from a config.json
        config_from_dict(WorldConfig, {**dataclasses.asdict(DEFAULT_WORLD), name: value})


@pytest.mark.parametrize(("name", "value", "says"), BAD_LEARNER)
def test_a_bad_learner_setting_is_refused_where_the_config_is_built(name, value, says):
    with pytest.raises(ValueError, match=f"LearnerConfig.{says}") as exc:
        LearnerConfig(**{name: value})
    _one_line(str(exc.value))


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        ({"n_names": 2}, "n_names must be 3"),
        ({"words": ("oey", "uyx", "iuo", "eyu", "eou", "yeo")}, "words must be distinct words"),
        ({"vowels": ("o", "o", "i", "e", "y")}, "vowels must be distinct single letters"),
        ({"recognition_distance": NAN}, "recognition_distance must be a finite number > 0"),
        ({"f1_offset": "8.5"}, "f1_offset must be a finite number, got '8.5'"),
        ({"study_vowel_hz": (("o", 500.0, -900.0),)}, "study_vowel_hz must be"),
    ],
)
def test_a_bad_voice_setting_is_refused(changes, says):
    with pytest.raises(ValueError, match=f"VoiceConfig.{says}"):
        dataclasses.replace(DEFAULT_VOICE, **changes)


def test_configs_from_json_lists_equal_the_defaults():
    """JSON gives lists where the configs hold tuples: the same config, still hashable."""
    world = json.loads(json.dumps(dataclasses.asdict(DEFAULT_WORLD)))
    assert config_from_dict(WorldConfig, world) == DEFAULT_WORLD
    assert world_preset("project", **{"segment_lengths": [0.25, 0.15, 0.1]}) == DEFAULT_WORLD
    voice = json.loads(json.dumps(dataclasses.asdict(DEFAULT_VOICE)))
    assert hash(config_from_dict(VoiceConfig, voice)) == hash(DEFAULT_VOICE)


# A trial with a bad setting writes nothing --------------------------------------------------
BAD_OVERRIDES = [
    ({"world": {name: value}}, says) for name, value, says in BAD_WORLD if name != "stick_return"
] + [
    ({"learner": {"exploration_sigma": "0.1"}}, "exploration_sigma must be a finite number"),
    # A length the MJCF model does not have fails when the room is built: now before writing.
    ({"world": {"stick_length": 0.3}}, "stick_length: model 0.25, config 0.3"),
    ({"world": {"grasp_distanse": 0.1}}, "unknown settings grasp_distanse"),
    ({"world": {"stick_return": "never"}}, "is the trial setting stick_return"),
    ({"learner": "sigma"}, "overrides.learner must be an object"),
]


@pytest.mark.parametrize(("overrides", "says"), BAD_OVERRIDES)
def test_a_trial_with_a_bad_override_is_refused_before_anything_is_written(
    tmp_path, overrides, says
):
    out = tmp_path / "t"
    with pytest.raises(TrialError, match=says) as exc:
        run_trial(out, TrialSettings(iterations=5, overrides=overrides), progress=False)
    _one_line(str(exc.value))
    assert not out.exists()


# The examples, which ran to their end with exit code 0: (--set, setting, range).
UNBOUNDED = [
    ("world.grasp_distance=1e308", "grasp_distance", "(0, 3.7]"),
    ("learner.exploration_sigma=1e308", "exploration_sigma", "[0, 2.0]"),
    ("world.dmp_weight_scale=1e308", "dmp_weight_scale", "(0, 30000]"),
    ("world.toy_replace_period=99999999999999999999999", "toy_replace_period", "[1, 2**63 - 1]"),
]


@pytest.mark.parametrize(("given", "name", "allowed"), UNBOUNDED)
def test_a_setting_beyond_its_range_is_one_line_naming_it_its_value_and_range(
    tmp_path, capsys, given, name, allowed
):
    out = tmp_path / "t"
    assert main(["run", "--out", str(out), "--iterations", "5", "--quiet", "--set", given]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    value = repr(json.loads(given.split("=")[1]))
    assert len(err) == 1 and f"{name} must be" in err[0], err
    assert f"in {allowed}, got {value}" in err[0], err[0]
    assert not out.exists()


def test_a_corrected_setting_runs_in_the_directory_a_typo_left(tmp_path):
    out = tmp_path / "t"
    with pytest.raises(TrialError, match="dmp must be one of"):
        run_trial(out, TrialSettings(iterations=5, overrides={"world": {"dmp": "studdy"}}))
    run_trial(out, TrialSettings(iterations=5, overrides={"world": {"dmp": "study"}}), False)
    assert storage.read_json(out / CONFIG_FILE)["world"]["dmp"] == "study"


@pytest.mark.parametrize(("name", "value", "says"), BAD_WORLD[:8] + BAD_WORLD[11:15])
def test_a_stored_bad_setting_exits_2_with_one_line_and_changes_nothing(
    tmp_path, capsys, name, value, says
):
    """A config.json whose overrides were edited by hand: `playroom run --resume` refuses it."""
    out = tmp_path / "t"
    out.mkdir()
    overrides = {"world": {name: value}}
    config = {"trial": {**dataclasses.asdict(TrialSettings()), "overrides": overrides}}
    text = json.dumps(config)  # NaN and Infinity too: what a hand edit may leave
    (out / CONFIG_FILE).write_text(text)
    assert main(["run", "--out", str(out), "--resume", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and name in err, err
    assert sorted(p.name for p in out.iterdir()) == [CONFIG_FILE]
    assert (out / CONFIG_FILE).read_text() == text


# Standard JSON only -------------------------------------------------------------------------
def test_json_files_never_hold_nan_or_infinity(tmp_path):
    path = tmp_path / "x.json"
    for bad in (NAN, INF, -INF):
        with pytest.raises(ValueError):
            storage.write_json(path, {"a": [1.0, bad]})
    assert list(tmp_path.iterdir()) == []  # no file, no temporary left behind
    assert storage.finite_or_null({"a": [1.0, NAN], "b": {"c": INF}}) == {
        "a": [1.0, None],
        "b": {"c": None},
    }


def test_an_infinite_best_distance_is_null_in_eval_json_and_read_back_as_infinite(tmp_path):
    """Before its first voice movement a trial's best distances are infinite."""
    summary = {
        "competence": {k: 0.1 for k in ("all", "ring1", "ring2", "ring3")},
        "mean_error": 0.5,
        "mean_random_error": 0.6,
        "vocal": {"share_below_threshold": 0.0, "median_names": INF, "median_distractors": INF},
    }
    storage.write_json(tmp_path / "eval.json", storage.finite_or_null(summary))
    text = (tmp_path / "eval.json").read_text()
    assert "Infinity" not in text and "null" in text
    numbers = eval_numbers(tmp_path, storage.read_json(tmp_path / "eval.json"))
    assert numbers["median_names"] == math.inf and numbers["median_distractors"] == math.inf


def test_full_config_is_standard_json():
    config = full_config(TrialSettings())
    json.dumps(config, allow_nan=False)
    assert config["world"]["segment_lengths"] == list(DEFAULT_WORLD.segment_lengths)


# Resuming with the stored settings ----------------------------------------------------------
def _run(*args: str) -> int:
    return main(["run", *args, "--quiet"])


@pytest.fixture
def short_trial(tmp_path):
    """A finished 200-iteration kinematic trial, seed 0, written by `playroom run`."""
    out = tmp_path / "t"
    assert _run("--out", str(out), "--iterations", "200", "--checkpoint-every", "100") == 0
    return out


def _checkpoint_iteration(out) -> int:
    return storage.read_arrays(out / CHECKPOINT_FILE)[1]["iteration"]


def test_resume_without_settings_keeps_the_trial_as_configured(short_trial, capsys):
    config = (short_trial / CONFIG_FILE).read_text()
    assert _run("--out", str(short_trial), "--resume") == 0
    assert "200 iterations (kinematic, seed 0)" in capsys.readouterr().out
    assert (short_trial / CONFIG_FILE).read_text() == config  # not extended to 80000
    assert _checkpoint_iteration(short_trial) == 200


def test_resume_with_more_iterations_extends_the_trial(short_trial):
    assert _run("--out", str(short_trial), "--resume", "--iterations", "300") == 0
    assert storage.read_json(short_trial / CONFIG_FILE)["trial"]["iterations"] == 300
    assert _checkpoint_iteration(short_trial) == 300 and len(read_log(short_trial)) == 300


def test_resume_refuses_other_settings_all_in_one_message(short_trial, capsys):
    config, checkpoint = ((short_trial / f).read_bytes() for f in (CONFIG_FILE, CHECKPOINT_FILE))
    args = ["--grasp", "physical", "--seed", "5", "--iterations", "100", "--preset", "study"]
    assert _run("--out", str(short_trial), "--resume", *args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "--grasp physical (it has kinematic)" in err and "--seed 5 (it has 0)" in err
    assert "--iterations 100 (it has 200" in err and "--preset" not in err  # study matches
    assert (short_trial / CONFIG_FILE).read_bytes() == config
    assert (short_trial / CHECKPOINT_FILE).read_bytes() == checkpoint


def test_resume_keeps_the_stored_overrides(tmp_path):
    out = tmp_path / "t"
    settings = TrialSettings(iterations=20, overrides={"world": {"catch_rule": "held_stick"}})
    run_trial(out, settings, progress=False)
    assert resume_settings(out, {}) == settings
    assert resume_settings(out, {"iterations": 40}) == dataclasses.replace(settings, iterations=40)


@pytest.mark.parametrize("kind", ["missing", "empty", "file"])
def test_resume_where_there_is_no_trial_is_one_line_and_creates_nothing(tmp_path, capsys, kind):
    out = tmp_path / "t"
    if kind == "empty":
        out.mkdir()
    elif kind == "file":
        out.write_text("x")
    assert _run("--out", str(out), "--resume") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"no trial to resume in {out}" in err, err
    if kind == "missing":
        assert not out.exists()
    elif kind == "empty":
        assert list(out.iterdir()) == []
    else:
        assert out.read_text() == "x"


def test_a_trial_stored_with_a_bad_setting_is_refused_in_one_line(short_trial, capsys):
    """A config.json edited by hand (or written before the checks): eval and resume refuse it."""
    config = storage.read_json(short_trial / CONFIG_FILE)
    config["world"]["catch_rule"] = "held_stik"
    storage.write_json(short_trial / CONFIG_FILE, config)
    before = {p.name: p.read_bytes() for p in short_trial.iterdir() if p.is_file()}
    for argv in (
        ["eval", str(short_trial), "--quiet"],
        ["run", "--out", str(short_trial), "--resume"],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "catch_rule" in err and "held_stik" in err, err
    assert {p.name: p.read_bytes() for p in short_trial.iterdir() if p.is_file()} == before


def test_older_trials_keep_the_contact_limit_as_their_stick_return_reach():
    # New trials return the physical stick beyond the measured 0.53 m (docs/protocol.md D14);
    # a config.json written before the setting existed reads back with the rule it ran with,
    # the contact limit (None), and a trial's identity leaves that value out (its checkpoints
    # stay its own).
    assert DEFAULT_WORLD.stick_return_reach == 0.53
    assert with_added_settings({"world": {}})["world"]["stick_return_reach"] is None
    form = identity_form({"world": {"stick_return_reach": None, "dmp": "study"}})
    assert form["world"] == {"dmp": "study"}
    assert identity_form({"world": {"stick_return_reach": 0.53}})["world"] == {
        "stick_return_reach": 0.53
    }
