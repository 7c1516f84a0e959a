"""Unit tests of the learner package, with a synthetic world (no MuJoCo: only the world's plain
config modules are read, for the study's numbers)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from synthetic import SyntheticWorld

from experiments.bench import learner as bench
from learner.agent import Agent, Proposal
from learner.config import LearnerConfig
from learner.interest import InterestModel
from learner.sensorimotor_model import MODELS, SensorimotorModel
from sim.config import DEFAULT_WORLD
from sim.vocal.config import DEFAULT_VOICE

SMALL = LearnerConfig(bootstrap_arm=50, bootstrap_voice=50)


def _world(seed: int) -> SyntheticWorld:
    """A synthetic world with the study's numbers."""
    return SyntheticWorld(
        seed,
        segment_lengths=DEFAULT_WORLD.segment_lengths,
        grasp_distance=DEFAULT_WORLD.grasp_distance,
        recognition_distance=DEFAULT_VOICE.recognition_distance,
        replace_period=DEFAULT_WORLD.toy_replace_period,
    )


def _run(agent: Agent, world: SyntheticWorld, n: int) -> list[Proposal]:
    return [agent.play(world)[0] for _ in range(n)]


# ---------------------------------------------------------------- the 10 models


def test_the_ten_models_of_the_protocol() -> None:
    toy = {1: [2, 3], 2: [4, 5], 3: [6, 7]}
    expected = [
        ("arm", slice(0, 10), []),
        ("arm", slice(10, 20), [0, 1]),
        ("arm", slice(20, 30), [0, 1, 2, 3]),
        ("arm", slice(30, 40), [0, 1, 4, 5]),
        ("arm", slice(40, 50), [0, 1, 6, 7]),
        ("arm", slice(50, 60), [0, 1, 2, 3, 4, 5, 6, 7]),
        ("voice", slice(20, 30), toy[1] + [8, 9]),
        ("voice", slice(30, 40), toy[2] + [8, 9]),
        ("voice", slice(40, 50), toy[3] + [8, 9]),
        ("voice", slice(50, 60), []),
    ]
    assert [spec.number for spec in MODELS] == list(range(1, 11))
    config = LearnerConfig()
    for spec, (space, sensory, context) in zip(MODELS, expected, strict=True):
        model = SensorimotorModel(spec, config)
        assert spec.motor_space == space
        assert model.sensory_slice == sensory
        assert list(model.context_dims) == context
        assert model.motor_dim == {"arm": 21, "voice": 28}[space]
        assert spec.imitates_caregiver == (spec.number == 10)
    agent = Agent(config, rng=0)
    assert [agent.toy_models(i) for i in (1, 2, 3)] == [(2, 6), (3, 7), (4, 8)]


def _feedback(**blocks: np.ndarray) -> np.ndarray:
    s = np.zeros(60)
    names = ["hand", "stick", "toy1", "toy2", "toy3", "sound"]
    for name, value in blocks.items():
        k = names.index(name)
        s[10 * k : 10 * k + 10] = value
    return s


def _still(xy: tuple[float, float]) -> np.ndarray:
    return np.repeat(np.asarray(xy, dtype=float), 5)  # 5 x then 5 y


def test_storing_rule() -> None:
    config = LearnerConfig()
    context = np.array([-0.25, 0.0, 0.3, 0.3, 0.6, 0.0, 0.0, 0.9, 0.5, 0.5])
    hand_model = SensorimotorModel(MODELS[0], config)
    stick_model = SensorimotorModel(MODELS[1], config)
    toy1_model = SensorimotorModel(MODELS[2], config)
    sound_model = SensorimotorModel(MODELS[9], config)
    moving_hand = np.concatenate((np.linspace(0, 0.3, 5), np.linspace(0.5, 0.2, 5)))
    resting = dict(stick=_still((-0.25, 0.0)), toy1=_still((0.3, 0.3)))
    m = np.zeros(21)

    s = _feedback(hand=moving_hand, **resting)
    assert hand_model.update(m, context, s)
    assert not stick_model.update(m, context, s)
    assert not toy1_model.update(m, context, s)
    # Jitter below the tolerance is not a movement.
    s = _feedback(hand=moving_hand, stick=_still((-0.25, 0.0)), toy1=_still((0.3, 0.3 + 1e-4)))
    assert not toy1_model.update(m, context, s)
    # A toy moved before the first sample: all samples equal, but not where it started.
    s = _feedback(hand=moving_hand, stick=_still((-0.25, 0.0)), toy1=_still((0.1, 0.4)))
    assert toy1_model.update(m, context, s)
    # A toy moved during the movement.
    carried = np.concatenate((np.linspace(0.3, 0.1, 5), np.full(5, 0.3)))
    s = _feedback(hand=moving_hand, stick=_still((-0.25, 0.0)), toy1=carried)
    assert toy1_model.update(m, context, s)
    assert len(toy1_model) == 2
    np.testing.assert_array_equal(toy1_model.context[-1], context[[0, 1, 2, 3]])
    np.testing.assert_array_equal(toy1_model.sensory[-1], carried)
    # A still hand is not stored.
    assert not hand_model.update(m, context, _feedback(hand=_still((0.0, 0.5))))
    # Silence is not stored, a sound is.
    assert not sound_model.update(np.zeros(28), context, _feedback())
    assert sound_model.update(np.zeros(28), context, _feedback(sound=np.full(10, 0.2)))


def test_cross_learning_updates_every_model_of_the_motor_space_only() -> None:
    agent = Agent(SMALL, rng=0)
    context = np.array([-0.25, 0.0, 0.3, 0.3, 0.6, 0.0, 0.0, 0.9, 0.5, 0.5])
    while True:
        proposal = agent.propose(context)
        if proposal.motor_space == "arm":
            break
        silent = _feedback(
            stick=_still((-0.25, 0.0)),
            toy1=_still((0.3, 0.3)),
            toy2=_still((0.6, 0.0)),
            toy3=_still((0.0, 0.9)),
        )
        agent.learn(proposal, context, silent)  # silent, nothing moved: nothing stored
    carried = np.concatenate((np.linspace(0.3, 0.1, 5), np.full(5, 0.3)))
    s = _feedback(
        hand=carried,
        stick=_still((-0.25, 0.0)),
        toy1=carried,
        toy2=_still((0.6, 0.0)),
        toy3=_still((0.0, 0.9)),
        sound=np.full(10, 0.1),
    )
    agent.learn(proposal, context, s)
    assert [len(model) for model in agent.models] == [1, 0, 1, 0, 0, 1, 0, 0, 0, 0]
    m, distance = agent.models[2].inverse(context, carried)
    np.testing.assert_array_equal(m, proposal.m)
    assert distance == 0.0
    np.testing.assert_array_equal(agent.models[2].forward(proposal.m, context), carried)


def test_learn_checks_its_input() -> None:
    agent = Agent(SMALL, rng=0)
    context = np.zeros(10)
    proposal = agent.propose(context)
    with pytest.raises(ValueError, match="shape"):
        agent.learn(proposal, context, np.zeros(59))
    with pytest.raises(ValueError, match="NaN"):
        agent.learn(proposal, context, np.full(60, np.nan))
    with pytest.raises(ValueError, match="context"):
        agent.propose(np.zeros(9))
    other = Proposal("arm", np.zeros(21), None, None, "bootstrap", False)
    with pytest.raises(ValueError, match="last propose"):
        agent.learn(other, context, np.zeros(60))


# ---------------------------------------------------------------- agent


def test_bootstrap_is_500_arm_and_500_voice_shuffled() -> None:
    agent = Agent(LearnerConfig(), rng=3)
    world = _world(3)
    proposals = _run(agent, world, 1001)
    boot = proposals[:1000]
    spaces = [p.motor_space for p in boot]
    assert spaces.count("arm") == 500 and spaces.count("voice") == 500
    assert all(p.kind == "bootstrap" and p.model is None and p.goal is None for p in boot)
    assert all(p.m.shape == ({"arm": 21, "voice": 28}[p.motor_space],) for p in boot)
    assert all(np.all(np.abs(p.m) <= 1.0) for p in boot)
    # Shuffled: both spaces appear throughout, not in two blocks.
    assert 150 < spaces[:500].count("arm") < 350
    assert proposals[1000].kind in ("goal", "imitation") and proposals[1000].model is not None


def test_goal_babbling_uses_the_inverse_model_with_noise() -> None:
    config = LearnerConfig(bootstrap_arm=50, bootstrap_voice=50, exploration_sigma=0.0)
    agent = Agent(config, rng=5)
    world = _world(5)
    _run(agent, world, 100)
    for _ in range(200):
        context = world.context()
        proposal = agent.propose(context)
        assert proposal.goal.shape == (10,) and np.all(np.abs(proposal.goal) <= 1.0)
        model = agent.models[proposal.model]
        if proposal.inferred:
            expected, _ = model.inverse(context, proposal.goal)
            np.testing.assert_array_equal(proposal.m, expected)
        agent.learn(proposal, context, world.act(proposal.motor_space, proposal.m).s)
    # With noise, commands differ from the nearest experience but stay in bounds.
    noisy = Agent(SMALL, rng=5)
    _run(noisy, _world(5), 100)
    context = world.context()
    for _ in range(20):
        proposal = noisy.propose(context)
        if proposal.inferred:
            expected, _ = noisy.models[proposal.model].inverse(context, proposal.goal)
            assert 0 < np.abs(proposal.m - expected).max() and np.all(np.abs(proposal.m) <= 1)


def test_imitation_draws_goals_from_heard_caregiver_sounds() -> None:
    agent = Agent(SMALL, rng=7)
    world = _world(7)
    _run(agent, world, 100)
    n_imitation = n_model10 = 0
    for _ in range(3000):
        context = world.context()
        heard = agent.heard_sounds
        proposal = agent.propose(context)
        if proposal.model == 9:
            n_model10 += 1
            if proposal.kind == "imitation":
                n_imitation += 1
                assert any(np.array_equal(proposal.goal, h) for h in heard)
                assert any(np.array_equal(proposal.goal, w) for w in world.words)
        else:
            assert proposal.kind == "goal"
        agent.learn(proposal, context, world.act(proposal.motor_space, proposal.m).s)
    assert n_model10 > 200
    assert abs(n_imitation / n_model10 - 0.5) < 0.1
    heard = agent.heard_sounds
    assert heard.shape == (100, 10)  # the last 100 only
    assert all(any(np.array_equal(h, w) for w in world.words) for h in heard)


def test_heard_sounds_come_from_arm_movements_only() -> None:
    agent = Agent(SMALL, rng=0)
    context = np.zeros(10)
    for _ in range(30):
        proposal = agent.propose(context)
        sound = np.full(10, 0.3 if proposal.motor_space == "arm" else -0.3)
        agent.learn(proposal, context, _feedback(sound=sound))
    assert len(agent.heard_sounds) > 0
    assert np.all(agent.heard_sounds == 0.3)


def test_same_seed_same_run_and_restored_agent_continues_identically(savez_round_trip) -> None:
    def proposals_of(agent: Agent, world: SyntheticWorld, n: int) -> list[np.ndarray]:
        return [p.m for p in _run(agent, world, n)]

    config = LearnerConfig(bootstrap_arm=50, bootstrap_voice=50, babbling="active")
    a, b = Agent(config, rng=11), Agent(config, rng=11)
    world_a, world_b = _world(4), _world(4)
    for x, y in zip(proposals_of(a, world_a, 400), proposals_of(b, world_b, 400), strict=True):
        np.testing.assert_array_equal(x, y)

    state = savez_round_trip(a.state_dict())
    restored = Agent(config, rng=999)  # a different seed: the state overrides it
    restored.load_state_dict(state)
    world_c = copy.deepcopy(world_a)
    after_a = proposals_of(a, world_a, 400)
    after_c = proposals_of(restored, world_c, 400)
    for x, y in zip(after_a, after_c, strict=True):
        np.testing.assert_array_equal(x, y)
    final_a, final_c = a.state_dict(), restored.state_dict()
    assert final_a.keys() == final_c.keys()
    for key in final_a:
        np.testing.assert_array_equal(final_a[key], final_c[key], err_msg=key)


def test_restore_refuses_another_config() -> None:
    state = Agent(SMALL, rng=0).state_dict()
    other = Agent(LearnerConfig(bootstrap_arm=50, bootstrap_voice=50, exploration_sigma=0.1))
    with pytest.raises(ValueError, match="exploration_sigma"):
        other.load_state_dict(state)


def test_learning_beats_random_commands_on_hand_goals() -> None:
    agent = Agent(LearnerConfig(), rng=2)
    world = _world(2)
    _run(agent, world, 2000)
    rng = np.random.default_rng(0)
    targets = [world.hand(m).T.ravel() for m in rng.uniform(-1, 1, (50, 21))]
    learnt = [
        np.linalg.norm(world.hand(agent.exploit(0, np.zeros(10), g)).T.ravel() - g) for g in targets
    ]
    random = [
        np.linalg.norm(world.hand(m).T.ravel() - g)
        for m, g in zip(rng.uniform(-1, 1, (50, 21)), targets, strict=True)
    ]
    assert np.mean(learnt) < 0.5 * np.mean(random)
    # nearest_distance (what evaluation compares models by) is the distance from (c_i, goal)
    # to the nearest stored (c_i, s_i), as a scan of every stored row finds it.
    # A model without experience is infinitely far from every goal.
    filled = 0
    for k, model in enumerate(agent.models):
        stored = np.hstack((model.context, model.sensory))
        filled += len(stored) > 0
        for goal in targets[:3]:
            context = world.context()
            key = np.concatenate((context[model.context_dims], goal))
            expected = np.linalg.norm(stored - key, axis=1).min() if len(stored) else np.inf
            got = agent.nearest_distance(k, context, goal)
            assert got == pytest.approx(expected, rel=1e-9, abs=1e-12), (k, got, expected)
    assert filled >= 5


# ---------------------------------------------------------------- interest


def test_active_interest_prefers_a_model_with_progress() -> None:
    config = LearnerConfig(babbling="active", progress_window=20)
    interest = InterestModel(2, config)
    rng = np.random.default_rng(0)
    goal = np.zeros(10)
    for k in range(40):
        interest.update(0, goal, np.full(10, 1.0 - k / 40))  # getting better
        interest.update(1, goal, np.full(10, 0.5))  # flat
    progress = interest.progress()
    assert progress[0] > 0.1 and progress[1] == 0.0
    choices = np.array([interest.choose(rng) for _ in range(2000)])
    # 80% by progress (all to model 0) + 20% uniform (half to model 0).
    assert abs(np.mean(choices == 0) - 0.9) < 0.03


def test_interest_without_progress_chooses_uniformly() -> None:
    interest = InterestModel(4, LearnerConfig(babbling="active"))
    rng = np.random.default_rng(0)
    counts = np.bincount([interest.choose(rng) for _ in range(4000)], minlength=4)
    assert np.all(np.abs(counts / 4000 - 0.25) < 0.03)


# ---------------------------------------------------------------- config and bench


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("babbling", "greedy"),
        ("exploration_sigma", -0.1),
        ("exploration_sigma", float("nan")),
        ("active_random_share", 1.5),
        ("imitation_share", -0.1),
        ("imitation_memory", 0),
        ("progress_window", 2.5),
        ("bootstrap_arm", -1),
        ("goal_low", 1.0),
        ("imitation_draw", "sometimes"),
        ("change_tolerance", float("inf")),
    ],
)
def test_config_validation(field: str, value: object) -> None:
    with pytest.raises(ValueError, match=field):
        LearnerConfig(**{field: value})


def test_config_defaults_and_round_trip() -> None:
    config = LearnerConfig()
    assert (config.bootstrap_arm, config.bootstrap_voice) == (500, 500)
    assert config.exploration_sigma == 0.05 and config.babbling == "random"
    assert config.active_random_share == 0.2 and config.imitation_share == 0.5
    assert config.imitation_memory == 100 and (config.goal_low, config.goal_high) == (-1, 1)
    assert LearnerConfig.from_dict(config.to_dict()) == config
    with pytest.raises(ValueError, match="unknown"):
        LearnerConfig.from_dict({"speed": 1})


def test_bench_checks_the_memory_against_brute_force_and_fills_the_models(monkeypatch):
    # Speed itself is measured by `playroom bench`; here: what the bench computes and checks.
    query = bench.query_ratio(n_rows=3000, dims=(10, 14), n_queries=20, repeats=1)
    assert query["n_rows"] == 3000 and sorted(query["by_dim"]) == [10, 14]
    assert query["ratio"] == max(d["ratio"] for d in query["by_dim"].values())
    for d in query["by_dim"].values():
        assert d["ratio"] == d["memory_s"] / d["brute_s"]
    # A memory answer that differs from brute force stops the bench.
    monkeypatch.setattr(bench, "brute_force_nearest", lambda rows, q: (-1, 0.0))
    with pytest.raises(AssertionError, match="brute force"):
        bench.query_ratio(n_rows=100, dims=(10,), n_queries=2, repeats=1)

    overhead = bench.learner_overhead(_world(1), n_rows=2000, n_iterations=20, babbling="active")
    assert overhead["n_rows"] == 2000 and overhead["babbling"] == "active"
    # Every model was filled to n_rows float64 rows of (m, c_i, s_i) before the timed part.
    motor_dim = {"arm": 21, "voice": 28}
    least = sum(8 * 2000 * (motor_dim[s.motor_space] + len(s.context_dims) + 10) for s in MODELS)
    assert overhead["model_bytes"] >= least
