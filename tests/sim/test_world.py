"""The world: MJCF model, DMPs, both grasp backends, the dm_control task, the Playroom."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from dm_control.rl import control
from scripted import Waypoint, arm_command_through

from models.layout import ARM_BASIS_FUNCTIONS, ARM_DIM, N_STEPS, VOICE_BASIS_FUNCTIONS, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.config import DEFAULT_WORLD, world_preset
from sim.dmp import arm_trajectory, voice_trajectory
from sim.grasping.names import GRASPS
from sim.kinematics import hand_positions
from sim.physics import PlayroomPhysics

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")

BACKENDS = list(GRASPS)  # every registered backend
# Toys parked in ring 3, away from every scripted path below.
PARKED_TOYS = np.array([[-0.75, -0.55], [-0.15, -0.9], [-0.8, 0.5]])


def test_model_forward_kinematics_match_the_protocol():
    physics = PlayroomPhysics.load()
    m, d = physics.model.ptr, physics.data.ptr
    rng = np.random.default_rng(0)
    for _ in range(100):
        q = rng.uniform(-np.pi, np.pi, 3)
        d.qpos[physics.arm_qpos] = q
        mujoco.mj_kinematics(m, d)
        np.testing.assert_allclose(physics.hand_position(), hand_positions(q), atol=1e-6)


def test_rest_pose_points_along_y_and_stick_starts_at_its_place():
    room = Playroom("kinematic", seed=0, config=PROJECT)
    np.testing.assert_allclose(room.physics.hand_position(), [0.0, 0.5], atol=1e-9)
    np.testing.assert_allclose(room.context()[:2], DEFAULT_WORLD.stick_start_handle, atol=1e-9)
    np.testing.assert_allclose(room.physics.stick_tip(), [-0.25, 0.25], atol=1e-9)


# DMPs ---------------------------------------------------------------------------------------
def test_zero_parameters_give_the_rest_trajectory():
    assert np.all(arm_trajectory(np.zeros(ARM_DIM)) == 0.0)
    assert np.all(voice_trajectory(np.zeros(VOICE_DIM)) == 0.0)


def test_end_parameter_sets_the_final_target():
    m = np.zeros((3, ARM_BASIS_FUNCTIONS + 1))
    m[:, -1] = [0.5, -0.3, 0.8]
    traj = arm_trajectory(m.ravel())
    np.testing.assert_allclose(traj[:, -1], np.pi * m[:, -1], atol=1e-3)
    voice = np.zeros((7, VOICE_BASIS_FUNCTIONS + 2))
    voice[:, 0], voice[:, 1] = -0.4, 0.6
    np.testing.assert_allclose(voice_trajectory(voice.ravel())[:, -1], 0.6, atol=1e-3)


def test_dmp_output_is_bounded_deterministic_and_shaped():
    rng = np.random.default_rng(1)
    for _ in range(50):
        m = rng.uniform(-1, 1, ARM_DIM)
        traj = arm_trajectory(m)
        assert traj.shape == (3, N_STEPS)
        assert np.abs(traj).max() <= np.pi
        np.testing.assert_array_equal(traj, arm_trajectory(m.copy()))
        v = voice_trajectory(rng.uniform(-1, 1, VOICE_DIM))
        assert v.shape == (7, N_STEPS) and np.abs(v).max() <= 1.0


# The dm_control task ------------------------------------------------------------------------
def test_room_starts_as_its_dm_control_task_starts_an_episode():
    room = Playroom("physical", seed=0, config=PROJECT)
    assert isinstance(room.task, control.Task)
    assert room.task.action_spec(room.physics).shape == (10,)
    obs = room.task.get_observation(room.physics)
    assert set(obs) == {"hand", "stick_handle", "stick_tip", "toys", "caregiver", "sound"}
    assert obs["toys"].shape == (3, 2)
    # The home keyframe: the arm at rest, the hand straight up from the base.
    np.testing.assert_allclose(obs["hand"], [0.0, room.config.arm_length], atol=1e-12)


def test_the_task_refuses_steps_pointing_to_where_commands_go():
    # Movements are computed whole by the backend: a dm_control step would act outside them.
    room = Playroom("kinematic", seed=0, config=PROJECT)
    state = room.get_state()
    with pytest.raises(RuntimeError, match="Playroom.act.*sim.envs"):
        room.task.before_step(np.r_[np.full(3, 0.5), np.zeros(7)], room.physics)
    np.testing.assert_array_equal(room.get_state()["physics"], state["physics"])


# Scripted motions, found by optimisation over the DMP parameters ---------------------------
def _command(waypoints: list[Waypoint]) -> np.ndarray:
    m, error = arm_command_through(waypoints)
    assert error < 0.02, f"no command follows the waypoints closely enough ({error:.3f} m)"
    return m


def _moved(feedback, name: str) -> bool:
    return any(e.kind in (ev.TOY_MOVED, ev.STICK_MOVED) and e.obj == name for e in feedback.events)


@pytest.mark.parametrize("grasp", BACKENDS)
def test_hand_on_handle_then_sweep_moves_the_stick(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    room.arrange(toys=PARKED_TOYS)
    hx, hy = room.context()[:2]
    # Come down beside the handle (not across the shaft), touch it, then sweep right.
    m = _command(
        [
            Waypoint(12, (hx - 0.15, hy + 0.2)),
            Waypoint(24, (hx - 0.04, hy + 0.02), np.pi / 2),
            Waypoint(50, (hx + 0.3, hy + 0.3)),
        ]
    )
    feedback = room.act_arm(m)
    assert ev.STICK_GRASPED in feedback.kinds()
    assert _moved(feedback, "stick")
    assert np.linalg.norm(room.context()[:2] - (hx, hy)) > 0.1


@pytest.mark.parametrize("grasp", BACKENDS)
def test_holding_the_stick_its_tip_moves_a_toy_in_ring_two(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    handle = np.array([0.15, 0.1])
    toy = np.array([0.6, 0.11])
    assert 0.5 < np.linalg.norm(toy) < 0.75, "the toy must lie beyond the hand's reach"
    # The stick lies along +x, its tip pointing at the toy.
    room.arrange(stick=(*handle, 0.0), toys=np.vstack([toy, PARKED_TOYS[1:]]))
    # Take the handle from behind, push the tip onto the toy along the stick, then sweep.
    m = _command(
        [
            Waypoint(16, tuple(handle + (-0.03, 0.02)), 0.0),
            Waypoint(20, tuple(handle + (-0.03, 0.02)), 0.0),
            Waypoint(34, tuple(handle + (0.19, 0.01)), 0.0),
            Waypoint(50, (0.3, 0.35), 0.8),
        ]
    )
    feedback = room.act_arm(m)
    assert ev.STICK_GRASPED in feedback.kinds() and ev.TOY_CAUGHT in feedback.kinds()
    moved = [e for e in feedback.events if e.kind == ev.TOY_MOVED and e.obj == "toy1"]
    assert moved and moved[0].by == "stick"
    assert np.linalg.norm(room.context()[2:4] - toy) > 0.1


@pytest.mark.parametrize("grasp", BACKENDS)
def test_hand_touching_a_toy_in_ring_one_moves_it(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    toy = np.array([0.2, 0.25])
    room.arrange(toys=np.vstack([toy, PARKED_TOYS[1:]]))
    m = _command([Waypoint(25, tuple(toy)), Waypoint(50, (0.35, 0.0))])
    feedback = room.act_arm(m)
    assert ev.TOY_GRASPED in feedback.kinds()
    assert _moved(feedback, "toy1")
    assert np.linalg.norm(room.context()[2:4] - toy) > 0.1


@pytest.mark.parametrize("grasp", BACKENDS)
def test_command_far_from_everything_moves_nothing(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    room.arrange(toys=PARKED_TOYS)
    before = room.context()
    m = _command([Waypoint(20, (0.2, 0.4)), Waypoint(40, (0.32, 0.2)), Waypoint(50, (0.25, 0.3))])
    feedback = room.act_arm(m)
    # Nothing happens but the caregiver's word after the movement: a distractor.
    assert feedback.kinds() == [ev.CAREGIVER_SAID]
    assert feedback.events[0].word in room.words.distractors
    # The objects' sensory blocks hold their unchanged positions.
    stick = feedback.s[10:20].reshape(2, 5)
    np.testing.assert_allclose(stick, np.repeat(before[:2, None], 5, axis=1), atol=1e-6)
    np.testing.assert_allclose(room.context()[:8], before[:8], atol=1e-6)


# Placements, caregiver, determinism ---------------------------------------------------------
def test_toys_are_replaced_every_20_iterations_in_the_rings_and_caregiver_every_iteration():
    room = Playroom("kinematic", seed=3, config=PROJECT)
    contexts = [room.context()]
    for _ in range(40):
        room.act_arm(np.zeros(ARM_DIM))
        contexts.append(room.context())
    contexts = np.array(contexts)
    toys = contexts[:, 2:8]
    assert np.all(toys[1:20] == toys[0]) and np.any(toys[20] != toys[19])
    radii = np.linalg.norm(toys.reshape(-1, 3, 2), axis=2)
    assert radii.max() <= 1.0
    caregiver = contexts[:, 8:]
    assert np.all(np.abs(caregiver) <= 1.0)
    assert len(np.unique(caregiver[:, 0])) == len(caregiver)
    assert np.all(contexts[:, :2] == contexts[0, :2])  # the stick is never reset


@pytest.mark.parametrize("grasp", BACKENDS)
def test_caregiver_brings_a_toy_toward_the_midpoint(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    room.arrange(toys=PARKED_TOYS, caregiver=(-0.8, 0.6))
    start = room.context()[2:4].copy()
    target = np.array([-0.4, 0.3])
    room.caregiver.start_bringing(room.physics, 0)
    room.act_voice(np.zeros(VOICE_DIM))
    moved = room.context()[2:4] - start
    expected = (1 - (1 - DEFAULT_WORLD.caregiver_bring_rate) ** N_STEPS) * (target - start)
    np.testing.assert_allclose(moved, expected, atol=0.03)


@pytest.mark.parametrize("grasp", BACKENDS)
def test_same_seed_same_contexts_and_feedbacks(grasp):
    rng = np.random.default_rng(7)
    commands = rng.uniform(-1, 1, (15, ARM_DIM))
    runs = []
    for _ in range(2):
        room = Playroom(grasp, seed=11, config=PROJECT)
        runs.append([(room.context(), room.act_arm(m).s) for m in commands])
    for (c1, s1), (c2, s2) in zip(*runs, strict=True):
        np.testing.assert_array_equal(c1, c2)
        np.testing.assert_array_equal(s1, s2)


def test_state_round_trip_continues_identically():
    rng = np.random.default_rng(2)
    room = Playroom("physical", seed=5, config=PROJECT)
    for m in rng.uniform(-1, 1, (5, ARM_DIM)):
        room.act_arm(m)
    state = room.get_state()
    commands = rng.uniform(-1, 1, (5, ARM_DIM))
    first = [room.act_arm(m).s for m in commands]
    other = Playroom("physical", seed=99, config=PROJECT)
    other.set_state(state)
    second = [other.act_arm(m).s for m in commands]
    np.testing.assert_array_equal(np.array(first), np.array(second))


# Bad input ----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("command", "message"),
    [
        (np.zeros(20), "shape"),
        (np.zeros((3, 7)), "shape"),
        (np.r_[np.zeros(20), np.nan], "NaN"),
        (np.r_[np.zeros(20), np.inf], "NaN or inf"),
        (np.r_[np.zeros(20), 1.5], r"\[-1, 1\]"),
        (["a"] * 21, "numbers"),
    ],
)
def test_bad_arm_commands_raise_and_leave_the_room_unchanged(command, message):
    room = Playroom("physical", seed=0, config=PROJECT)
    before, state = room.context(), room.get_state()
    with pytest.raises(ValueError, match=message):
        room.act_arm(command)
    np.testing.assert_array_equal(room.context(), before)
    np.testing.assert_array_equal(room.get_state()["physics"], state["physics"])
    assert room.iteration == state["iteration"]


def test_bad_voice_command_and_options_raise():
    room = Playroom("kinematic", seed=0, config=PROJECT)
    with pytest.raises(ValueError, match="voice command"):
        room.act_voice(np.zeros(21))
    with pytest.raises(ValueError, match="unknown grasp"):
        Playroom("magnetic")
    with pytest.raises(ValueError, match="seed"):
        Playroom("physical", seed=-1)
    with pytest.raises(ValueError, match="toys"):
        room.arrange(toys=np.zeros((2, 2)))


def test_diverging_physics_is_reported_and_undone():
    room = Playroom("physical", seed=0, config=PROJECT)
    before = room.context()
    # A timestep far too long for the stiff servos makes the simulation blow up.
    room.physics.model.ptr.opt.timestep = 5.0
    feedback = room.act_arm(np.full(ARM_DIM, 0.9))
    assert feedback.kinds() == [ev.DIVERGED]
    np.testing.assert_allclose(room.context()[:8], before[:8])
    assert np.all(np.isfinite(feedback.s))
    room.physics.model.ptr.opt.timestep = 0.002
    assert np.all(np.isfinite(room.act_arm(np.zeros(ARM_DIM)).s))
