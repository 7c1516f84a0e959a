"""The contract every registered vocal tract keeps, run for each name in models/tracts.py's
`REGISTRY`: a tract added there is tested here without editing this file.

Each tract is built as the room builds it (`make_tract`, in a world of that voice); it turns a
voice command into an articulator trajectory and that into formants, one row per control step,
the same through every path; it hears each of its own words' targets as that word; its words'
features are 10D; it sounds. A tract whose data is the user's (DIVA's) is skipped, saying so,
where that data is not installed here.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from models.layout import N_ARTICULATORS, N_STEPS, SAMPLE_INDICES, VOICE_DIM
from models.presets import DEFAULT_PRESET
from models.tracts import DEFAULT_TRACT, REGISTRY, TRACTS
from sim.config import world_preset
from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.registry import load, make_tract
from sim.vocal.voice import Voice
from sim.vocal.words import normalise

FEATURES = 2 * len(SAMPLE_INDICES)  # F1 then F2 at the 5 sample steps


@pytest.fixture(scope="module", params=TRACTS)
def tract(request: pytest.FixtureRequest) -> Voice:
    """The registered tract of this name, built as the room builds it."""
    name = request.param
    try:
        return make_tract(name, False, DEFAULT_VOICE, world_preset(DEFAULT_PRESET, voice=name))
    except load(name).user_data_errors as exc:
        pytest.skip(f"{name}: the user's data for it is not installed here ({exc})")


def test_the_table_names_each_tract_once_and_the_default_is_one_of_them() -> None:
    assert TRACTS == tuple(REGISTRY) and DEFAULT_TRACT in REGISTRY
    for target in REGISTRY.values():
        module, sep, class_name = target.partition(":")
        assert sep and module.startswith("sim.vocal.") and class_name.isidentifier(), target
    with pytest.raises(ValueError, match=", ".join(repr(n) for n in TRACTS)):
        load("no such tract")


def test_naming_the_tracts_imports_none_of_them() -> None:
    """The table is lazy: the registry imports a tract's module only when it is loaded."""
    code = (
        "import sys, sim.vocal.registry as r; "
        "print(*[m for m in (t.partition(':')[0] for t in r.REGISTRY.values()) "
        "if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


@pytest.mark.parametrize("name", TRACTS)
def test_a_tract_is_registered_under_its_own_name(name: str) -> None:
    cls = load(name)
    assert issubclass(cls, Voice) and cls.name == name
    assert isinstance(cls.sound_label, str) and cls.sound_label
    assert all(issubclass(e, Exception) for e in cls.user_data_errors)


def test_a_built_tract_is_the_registered_class_in_its_world(tract: Voice) -> None:
    assert type(tract) is load(tract.name)
    assert tract.world.voice == tract.name and tract.config == DEFAULT_VOICE
    record = tract.data_record()
    assert all(isinstance(k, str) and isinstance(v, str) for k, v in record.items())


def test_a_command_gives_formants_for_each_step_the_same_through_every_path(
    tract: Voice,
) -> None:
    rng = np.random.default_rng(0)
    for m in rng.uniform(-1.0, 1.0, (4, VOICE_DIM)):
        traj = tract.trajectory(m)
        assert traj.shape == (N_ARTICULATORS, N_STEPS)
        steps = tract.trajectory_formants(traj)
        assert steps.shape == (N_STEPS, 2) and np.all(np.isfinite(steps))
        np.testing.assert_array_equal(steps, tract.formants(traj.T))
        assert tract.formants(traj[:, 0]).shape == (2,)
        features = tract.features_from_formants(steps)
        assert features.shape == (FEATURES,)
        # The sound sensor's features (every step) and the learner's (the 5 samples only).
        np.testing.assert_allclose(tract.sound_features(m), features, rtol=0, atol=1e-12)
        rows = np.array(SAMPLE_INDICES)
        fewer = tract.frame_formants_at(traj.T, rows)
        if fewer is not None:
            np.testing.assert_allclose(fewer, steps[rows], rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
        tract.formants(np.full(N_ARTICULATORS, 1.5))


def test_a_tract_hears_each_of_its_words_targets_as_that_word(tract: Voice) -> None:
    for word in tract.config.words:
        target = tract.word_trajectory(word)  # (5, 2) log2 Hz between its vowel targets
        assert target.shape == (len(SAMPLE_INDICES), 2)
        features = normalise(target, tract.config)
        np.testing.assert_array_equal(features, tract.word_features(word))
        assert tract.recognise(features) == word
        assert tract.word_distances(features).argmin() == tract.config.words.index(word)


def test_word_features_are_10d_one_row_per_word_and_read_only(tract: Voice) -> None:
    words = tract.config.words
    assert set(tract.vowel_targets()) == set(tract.config.vowels)
    assert all(tract.word_features(w).shape == (FEATURES,) for w in words)
    table = tract.all_word_features()
    assert table.shape == (len(words), FEATURES) and not table.flags.writeable
    assert tract.word_distances(np.zeros((3, FEATURES))).shape == (3, len(words))
    with pytest.raises(ValueError, match="unknown word"):
        tract.word_features("aaa")


def test_a_tract_sounds_its_words(tract: Voice) -> None:
    wave, rate = tract.word_audio(tract.config.words[0])
    assert wave.ndim == 1 and wave.size > 0 and np.all(np.isfinite(wave))
    assert isinstance(rate, int) and rate > 0
