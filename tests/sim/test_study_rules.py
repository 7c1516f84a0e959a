"""The `study` preset behaves as the study's code did (docs/protocol.md §11 D1-D10), each rule
checked on its own; the `project` preset keeps the earlier choices."""

from __future__ import annotations

import numpy as np
import pytest

from learner.agent import Agent
from learner.config import learner_preset
from learner.sensorimotor_model import SensorimotorModel
from models.layout import ARM_DIM, MODELS, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.config import DEFAULT_WORLD, world_preset
from sim.dmp import arm_trajectory, voice_trajectory

STUDY_WORLD = world_preset("study")
PARKED = np.array([[0.9, -0.9], [-0.9, -0.9], [0.0, -0.95]])  # far from everything


def study_dmp(start: np.ndarray, goal: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The study's DMP written out (dmp/cs.py, dmp_discrete.py): per dimension, 50 steps of
    y <- y + 0.0625 (g - y) + 0.0004 f with f = x sum(psi w) / sum(psi), x_t = 0.98^t,
    centres exp(-d) for d evenly from 0.9 to 0, widths 8 n^2 / c^1.5."""
    n = weights.shape[1]
    centres = np.exp(-np.linspace(0.9, 0.0, n))
    widths = 8 * n**2 / centres**1.5
    out = np.empty((len(start), 50))
    for d in range(len(start)):
        y, x = start[d], 1.0
        for t in range(50):
            psi = np.exp(-widths * (x - centres) ** 2)
            f = x * (psi @ weights[d]) / psi.sum()
            y = y + 0.0625 * (goal[d] - y) + 0.0004 * f
            out[d, t] = y
            x = 0.98 * x
    return out


def test_the_study_dmp_follows_its_equations():
    rng = np.random.default_rng(0)
    for _ in range(20):
        m = rng.uniform(-1, 1, ARM_DIM)
        per_joint = m.reshape(3, 7)
        expected = np.pi * np.clip(
            study_dmp(np.zeros(3), per_joint[:, -1], 300 * per_joint[:, :-1]), -1, 1
        )
        np.testing.assert_allclose(arm_trajectory(m, STUDY_WORLD), expected, atol=1e-12)
        v = rng.uniform(-1, 1, VOICE_DIM).reshape(7, 4)
        expected = np.clip(study_dmp(v[:, 0], v[:, 1], 300 * v[:, 2:]), -1, 1)
        np.testing.assert_allclose(voice_trajectory(v.ravel(), STUDY_WORLD), expected, atol=1e-12)
    # Without weights the study's first-order DMP reaches only 96% of the way to its goal.
    rest_to_one = arm_trajectory(np.tile([0, 0, 0, 0, 0, 0, 1 / np.pi], 3), STUDY_WORLD)
    assert rest_to_one[0, -1] == pytest.approx(1 - 0.9375**50, abs=1e-12)


def test_a_lying_stick_catches_a_toy_near_its_tip_in_the_study_world_only():
    tip = np.array(DEFAULT_WORLD.stick_start_handle) + (0.0, DEFAULT_WORLD.stick_length)
    toys = np.vstack([tip + (0.06, 0.0), PARKED[1:]])
    still_arm = np.zeros(ARM_DIM)  # the hand stays at rest, 0.25 m from the tip's toy
    for config, caught in ((STUDY_WORLD, True), (DEFAULT_WORLD, False)):
        room = Playroom("kinematic", seed=0, config=config)
        room.arrange(toys=toys)
        feedback = room.act("arm", still_arm)
        assert (ev.TOY_CAUGHT in feedback.kinds()) == caught
        if caught:
            np.testing.assert_allclose(feedback.positions[-1, 2], tip, atol=1e-12)
            assert any(e.kind == ev.TOY_MOVED and e.by == "stick" for e in feedback.events)


def test_the_resting_hand_takes_a_stick_within_reach_during_a_vocal_movement():
    rest = np.array([0.0, 0.5])
    for config, grasped in ((STUDY_WORLD, True), (DEFAULT_WORLD, False)):
        room = Playroom("kinematic", seed=0, config=config)
        room.arrange(stick=(*(rest + (0.05, -0.05)), 0.0), toys=PARKED)
        feedback = room.act("voice", np.zeros(VOICE_DIM))
        assert (ev.STICK_GRASPED in feedback.kinds()) == grasped
        handle = room.context()[:2]
        assert np.allclose(handle, rest) == grasped


def _learn_arm(agent: Agent, context: np.ndarray, s: np.ndarray) -> None:
    """One arm iteration whose feedback is `s`, whatever the agent proposes."""
    proposal = agent.propose(context)
    while proposal.motor_space != "arm":
        agent.learn(proposal, context, np.zeros(60))
        proposal = agent.propose(context)
    agent.learn(proposal, context, s)


def _sound(value: float) -> np.ndarray:
    s = np.zeros(60)
    s[50:] = value
    return s


def test_imitation_draws_from_every_word_ever_heard_in_the_study_preset():
    context = np.zeros(10)
    for pool, remembers_first in (("all_heard", True), ("recent", False)):
        agent = Agent(learner_preset("project", imitation_pool=pool, bootstrap_arm=0,
                                     bootstrap_voice=0), rng=0)  # fmt: skip
        _learn_arm(agent, context, _sound(0.1))
        for _ in range(150):  # more than the 100 recent sounds
            _learn_arm(agent, context, _sound(0.2))
        goals = {float(agent._imitation_goal()[0]) for _ in range(200)}
        assert (0.1 in goals) == remembers_first and 0.2 in goals


def test_the_study_stores_a_block_only_when_its_samples_vary():
    context = np.array([-0.25, 0.0, 0.3, 0.3, 0.6, 0.0, 0.0, 0.9, 0.5, 0.5])
    held_still = np.zeros(60)
    held_still[20:30] = np.repeat([0.1, 0.5], 5)  # toy1 taken before step 1, held still
    moving = held_still.copy()
    moving[20:25] = np.linspace(0.1, 0.3, 5)
    for rule, stores_still in (("varies_about_mean", False), ("moved_from_start", True)):
        toy1 = SensorimotorModel(MODELS[2], learner_preset("project", storing_rule=rule))
        assert toy1.update(np.zeros(ARM_DIM), context, held_still) == stores_still
        assert toy1.update(np.zeros(ARM_DIM), context, moving)


def test_the_study_clips_the_feedback_before_learning():
    context = np.zeros(10)
    s = np.zeros(60)
    s[0:5] = np.linspace(0.0, 1.6, 5)  # the hand block varies, beyond 1
    for clip, top in ((True, 1.0), (False, 1.6)):
        agent = Agent(learner_preset("project", clip_sensory=clip, bootstrap_arm=0,
                                     bootstrap_voice=0), rng=1)  # fmt: skip
        _learn_arm(agent, context, s)
        assert agent.models[0].sensory.max() == pytest.approx(top)


def test_the_study_bootstrap_tosses_coins_learns_nothing_and_waits_for_two_outcomes():
    config = learner_preset("study")
    assert config.exploration_sigma == 0.1
    agent = Agent(config, rng=3)
    context = np.zeros(10)
    spaces = []
    for _ in range(config.n_bootstrap):
        proposal = agent.propose(context)
        spaces.append(proposal.motor_space)
        agent.learn(proposal, context, _sound(0.3))
    assert spaces.count("arm") != 500 and 400 < spaces.count("arm") < 600  # coin tosses
    assert all(len(model) == 0 for model in agent.models)  # nothing learned
    # After one outcome a model still acts at random; after a second, different one it infers.
    agent = Agent(learner_preset("study", bootstrap_arm=0, bootstrap_voice=0), rng=4)
    for value in (0.1, 0.2):
        for model in agent.models:
            s = np.zeros(60)
            s[model.sensory_slice] = np.linspace(0, value, 10)
            model.store(np.zeros(model.motor_dim), context, s)
        inferred = set()
        for _ in range(30):
            proposal = agent.propose(context)
            inferred.add(proposal.inferred)
            agent.learn(proposal, context, np.zeros(60))
        assert inferred == {value == 0.2}


def test_a_trial_can_switch_one_departure_back(tmp_path):
    from experiments.run.settings import TrialSettings
    from experiments.run.trial import run_trial
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError

    overrides = {"learner": {"exploration_sigma": 0.05}, "world": {"dmp": "project"}}
    settings = TrialSettings(iterations=5, overrides=overrides)
    run_trial(tmp_path / "t", settings, progress=False)
    config = storage.read_json(tmp_path / "t" / "config.json")
    assert config["learner"]["exploration_sigma"] == 0.05 and config["world"]["dmp"] == "project"
    assert config["learner"]["storing_rule"] == "varies_about_mean"  # the rest: the study's
    with pytest.raises(TrialError, match="overrides"):
        run_trial(tmp_path / "u", TrialSettings(overrides={"learner": {"sigma": 1}}))
    assert not (tmp_path / "u" / "config.json").exists()
