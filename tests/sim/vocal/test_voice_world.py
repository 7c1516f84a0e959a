"""The voice inside the world: the sound sensor, the caregiver's words and her reactions."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import wavfile
from scripted import Waypoint, arm_command_through

from experiments.cli.main import main
from models.layout import ARM_DIM, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.config import world_preset
from sim.vocal.vtl.productions import say
from sim.vocal.vtl.words import word_distances, word_features

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")

BACKENDS = ["kinematic", "physical"]


@pytest.mark.parametrize("grasp", BACKENDS)
def test_sound_block_is_the_agents_own_sound_after_a_vocal_movement(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    m = np.random.default_rng(0).uniform(-1, 1, VOICE_DIM)
    feedback = room.act_voice(m)
    np.testing.assert_allclose(feedback.s[50:], room.vocal_tract.sound_features(m), atol=1e-12)
    # The sensor reads the sound at every control step; the samples make the features.
    assert feedback.sound.shape == (50, 2) and np.all(feedback.sound != 0)


@pytest.mark.parametrize("grasp", BACKENDS)
def test_saying_a_toys_name_makes_the_caregiver_bring_it(grasp):
    room = Playroom(grasp, seed=1, config=PROJECT)
    toy = 2  # toy3, parked far away in ring 3
    room.arrange(toys=[[-0.5, -0.9], [0.9, -0.3], [0.7, 0.7]], caregiver=(0.9, 0.9))
    name = room.words.names[toy]
    start = room.context()[2 + 2 * toy : 4 + 2 * toy].copy()
    feedback = room.act_voice(say(name))
    heard = [e for e in feedback.events if e.kind == ev.WORD_RECOGNISED]
    assert heard and heard[0].word == name and heard[0].obj == "toy3"
    moved = [e for e in feedback.events if e.kind == ev.TOY_MOVED]
    assert [(e.obj, e.by) for e in moved] == [("toy3", "caregiver")]
    end = room.context()[2 + 2 * toy : 4 + 2 * toy]
    target = np.array([0.45, 0.45])  # midpoint between her and the base
    assert np.linalg.norm(end - target) < 0.7 * np.linalg.norm(start - target)


@pytest.mark.parametrize("grasp", BACKENDS)
def test_a_distractor_is_recognised_but_brings_nothing(grasp):
    room = Playroom(grasp, seed=1, config=PROJECT)
    word = room.words.distractors[0]
    before = room.context()[:8]
    feedback = room.act_voice(say(word))
    assert [(e.kind, e.word, e.obj) for e in feedback.events] == [(ev.WORD_RECOGNISED, word, None)]
    np.testing.assert_allclose(room.context()[:8], before, atol=1e-6)


@pytest.mark.parametrize("grasp", BACKENDS)
def test_caregiver_names_the_toy_in_the_hand_else_a_distractor(grasp):
    room = Playroom(grasp, seed=2, config=PROJECT)
    toy = np.array([0.2, 0.25])
    room.arrange(toys=[toy, [-0.15, -0.9], [-0.8, 0.5]])
    m, _ = arm_command_through([Waypoint(25, tuple(toy)), Waypoint(50, (0.3, 0.1))])
    feedback = room.act_arm(m)
    said = [e for e in feedback.events if e.kind == ev.CAREGIVER_SAID]
    assert said[0].word == room.words.names[0] and said[0].obj == "toy1"
    np.testing.assert_allclose(feedback.s[50:], word_features(said[0].word))
    feedback = room.act_arm(np.zeros(ARM_DIM))
    said = [e for e in feedback.events if e.kind == ev.CAREGIVER_SAID]
    assert said[0].word in room.words.distractors
    assert word_distances(feedback.s[50:]).min() < 1e-12


def test_words_are_shuffled_per_seed_into_names_and_distractors():
    assignments = {Playroom("kinematic", seed=s, config=PROJECT).words for s in range(6)}
    assert len(assignments) > 1
    for words in assignments:
        assert len(set(words.names) | set(words.distractors)) == 6


def test_exact_voice_option_gives_the_same_words():
    exact = Playroom("kinematic", seed=0, exact_voice=True, config=PROJECT)
    word = exact.words.names[0]
    feedback = exact.act_voice(say(word))
    assert word_distances(feedback.s[50:])[list(exact.vocal_tract.config.words).index(word)] < 0.4
    assert np.all(np.isfinite(feedback.s))


def test_bad_voice_command_leaves_the_room_unchanged():
    room = Playroom("physical", seed=0, config=PROJECT)
    before = room.get_state()
    for bad in (np.zeros(27), np.full(28, np.nan), np.full(28, 2.0)):
        with pytest.raises(ValueError, match="voice command"):
            room.act_voice(bad)
    np.testing.assert_array_equal(room.get_state()["physics"], before["physics"])


def test_say_writes_the_word_as_audio(tmp_path, capsys):
    out = tmp_path / "oey.wav"
    assert main(["say", "oey", "--out", str(out)]) == 0
    rate, data = wavfile.read(out)
    assert rate == 44100 and data.dtype == np.int16 and len(data) > 0.4 * rate
    assert np.abs(data).max() > 1000  # not silence
    assert main(["say", "xyz", "--out", str(out)]) == 2
    assert main(["say", "oey", "--out", str(tmp_path / "no" / "a.wav")]) == 2
