"""The contact ladder's rungs 3 and 4 differ by where the physical backend holds what it takes
(WorldConfig.held_pose): at the pose of the touch ("touch", D16), or placed as the
kinematic rules hold it ("aligned": the stick's handle at the hand along the last segment, a
toy at the hand or at the held stick's tip), the weld then keeping that pose."""

from __future__ import annotations

import numpy as np
import pytest
from scripted import Waypoint, arm_command_through
from stepped_oracle import use_oracle

from models.layout import ARM_DIM, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.config import inert_settings, world_preset

PARKED_TOYS = np.array([[-0.75, -0.55], [-0.15, -0.9], [-0.8, 0.5]])
HANDLE = np.array([0.15, 0.1])
TOY_ON_STICK_LINE = np.array([0.6, 0.11])
TOY_IN_REACH = np.array([0.2, 0.25])
# The welds are soft (solref 0.004 s in models/playroom.xml): while the arm moves, what they
# hold strays from their pose, in these scenes by up to 1.4 mm and 3.3 mrad (the stick) and
# 4.8 mm (a toy in the hand).
WELD_SLACK_M, WELD_SLACK_RAD = 6e-3, 1e-2


def _command(waypoints: list[Waypoint]) -> np.ndarray:
    m, error = arm_command_through(waypoints)
    assert error < 0.02, f"no command follows the waypoints closely enough ({error:.3f} m)"
    return m


def _tool_use(room: Playroom) -> np.ndarray:
    """The hand takes the stick lying along +x, whose tip then reaches a toy on that line."""
    room.arrange(stick=(*HANDLE, 0.0), toys=np.vstack([TOY_ON_STICK_LINE, PARKED_TOYS[1:]]))
    return _command(
        [
            Waypoint(16, tuple(HANDLE + (-0.03, 0.02)), 0.0),
            Waypoint(20, tuple(HANDLE + (-0.03, 0.02)), 0.0),
            Waypoint(34, tuple(HANDLE + (0.19, 0.01)), 0.0),
            Waypoint(50, (0.3, 0.35), 0.8),
        ]
    )


def _offsets(held_pose: str, scene) -> tuple[list[ev.Event], np.ndarray]:
    """Events of the scene's movement, and after each control step: the stick's handle from
    the hand (m), its yaw from the hand's (rad), toy1 from the stick's tip and from the hand
    (m), as (50, 4)."""
    # The project's DMP: the one scripted commands are fitted to (tests/scripted.py).
    room = Playroom("physical", seed=0, config=world_preset("project", held_pose=held_pose))
    room.tracing = True
    rows: list[list[float]] = []
    events = room.act_arm(scene(room)).events
    assert room.last_trace is not None
    for _, p in room.last_trace.replayed(room.physics):
        stick = p.object_poses()[0]
        hand, tip, toy = p.hand_position(), p.stick_tip(), p.toy_positions()[0]
        turn = (stick[2] - p.hand_angle() + np.pi) % (2 * np.pi) - np.pi
        distance = lambda a, b: float(np.hypot(*(a - b)))  # noqa: E731
        rows.append([distance(stick[:2], hand), abs(turn), distance(toy, tip), distance(toy, hand)])
    return events, np.array(rows)


def _step(events: list[ev.Event], kind: str) -> int:
    return next(e.step for e in events if e.kind == kind)


def test_an_aligned_stick_is_held_as_the_kinematic_rules_hold_it_and_its_catch_at_the_tip():
    events, offsets = _offsets("aligned", _tool_use)
    grasped, caught = _step(events, ev.STICK_GRASPED), _step(events, ev.TOY_CAUGHT)
    # Placed at the touch's step: the handle at the hand, along the last segment.
    assert offsets[grasped - 1, 0] < 1e-9 and offsets[grasped - 1, 1] < 1e-9
    assert (offsets[grasped:, 0] < WELD_SLACK_M).all()
    assert (offsets[grasped:, 1] < WELD_SLACK_RAD).all()
    assert offsets[caught - 1, 2] < 1e-9 and (offsets[caught:, 2] < WELD_SLACK_M).all()
    # At the touch's pose, the same grasp holds the stick by its contact offset.
    events, offsets = _offsets("touch", _tool_use)
    grasped = _step(events, ev.STICK_GRASPED)
    assert (offsets[grasped - 1 :, 0] > 0.02).all()


def test_a_stick_placed_on_a_toy_catches_it_in_its_grasps_step():
    """As under the kinematic rules, the tip catches where the grasp put the stick, in the
    same step: the contacts are found again for the placed stick (not a step later)."""
    reach = HANDLE + (-0.03, 0.0)  # the hand comes down on the handle pointing along +y

    def grasp_over_toy(room: Playroom) -> np.ndarray:
        toys = np.vstack([reach + (0.0, 0.25), PARKED_TOYS[1:]])  # where the tip will be
        room.arrange(stick=(*HANDLE, 0.0), toys=toys)
        return _command(
            [
                Waypoint(16, tuple(reach), np.pi / 2),
                Waypoint(22, tuple(reach), np.pi / 2),
                Waypoint(50, (0.0, 0.4)),
            ]
        )

    events, offsets = _offsets("aligned", grasp_over_toy)
    grasped = _step(events, ev.STICK_GRASPED)
    assert _step(events, ev.TOY_CAUGHT) == grasped and offsets[grasped - 1, 2] < 1e-9
    events, _ = _offsets("touch", grasp_over_toy)  # the stick along +x: its tip far from it
    assert ev.TOY_CAUGHT not in {e.kind for e in events}


def test_an_aligned_toy_in_the_hand_is_at_the_hand():
    def take_toy(room: Playroom) -> np.ndarray:
        room.arrange(toys=np.vstack([TOY_IN_REACH, PARKED_TOYS[1:]]), caregiver=(-0.8, 0.6))
        return _command([Waypoint(25, tuple(TOY_IN_REACH)), Waypoint(50, (0.35, 0.0))])

    events, offsets = _offsets("aligned", take_toy)
    grasped = _step(events, ev.TOY_GRASPED)
    assert offsets[grasped - 1, 3] < 1e-9 and (offsets[grasped:, 3] < WELD_SLACK_M).all()
    events, offsets = _offsets("touch", take_toy)
    assert (offsets[_step(events, ev.TOY_GRASPED) - 1 :, 3] > 0.02).all()


def test_aligned_holds_give_the_same_numbers_on_every_path():
    """The compiled steps and the step-by-step Python loop (tests/stepped_oracle.py) place and
    weld alike (the placement recomputes the room's forces on both), and trace alike."""
    config = world_preset("project", held_pose="aligned", push_objects=False)
    rooms = [Playroom("physical", seed=1, config=config) for _ in range(2)]
    use_oracle(rooms[1])
    for room in rooms:
        room.tracing = True
    rng = np.random.default_rng(1)
    commands = [_tool_use] + [
        ("arm", rng.uniform(-1, 1, ARM_DIM)) if i % 3 else ("voice", rng.uniform(-1, 1, VOICE_DIM))
        for i in range(90)
    ]
    kinds: set[str] = set()
    for command in commands:
        feedbacks = [
            room.act_arm(command(room)) if callable(command) else room.act(*command)
            for room in rooms
        ]
        for other, room in zip(feedbacks[1:], rooms[1:], strict=True):
            np.testing.assert_array_equal(other.positions, feedbacks[0].positions)
            assert other.events == feedbacks[0].events
            np.testing.assert_array_equal(room.physics.data.qpos, rooms[0].physics.data.qpos)
            np.testing.assert_array_equal(room.last_trace.qpos, rooms[0].last_trace.qpos)
        kinds.update(feedbacks[0].kinds())
    assert {ev.STICK_GRASPED, ev.TOY_GRASPED, ev.TOY_CAUGHT} <= kinds


def test_the_switch_is_the_physical_backends_and_checked():
    with pytest.raises(ValueError, match="held_pose"):
        world_preset("study", held_pose="aligned_")
    assert inert_settings("kinematic", {"held_pose": "aligned"}) == ["held_pose"]
    assert inert_settings("physical", {"held_pose": "aligned"}) == []
