"""The physical movement's control steps run compiled (sim/compiled_steps.py): the same numbers,
events, trace and state as the step-by-step Python loop (tests/stepped_oracle.py), and the
contact sensors they watch say what MuJoCo's contact list says."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scripted import Waypoint, arm_command_through
from stepped_oracle import use_oracle

from models import playroom_xml
from models.layout import ARM_DIM, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.compiled_steps import AVAILABLE, SENSORS_OFF, disable_flags_view
from sim.config import world_preset
from sim.physics import GRASP_CONTACTS, PlayroomPhysics

PROJECT = world_preset("project")
PARKED_TOYS = np.array([[-0.75, -0.55], [-0.15, -0.9], [-0.8, 0.5]])
HANDLE = np.array([0.15, 0.1])
TOY_ON_STICK_LINE = np.array([0.6, 0.11])
TOY_IN_REACH = np.array([0.2, 0.25])
BRING = "bring"  # a scene's step: the caregiver starts bringing toy m (0-based)

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="MuJoCo's shared library not found")


def _command(waypoints: list[Waypoint]) -> np.ndarray:
    m, error = arm_command_through(waypoints)
    assert error < 0.02, f"no command follows the waypoints closely enough ({error:.3f} m)"
    return m


def _tool_scene(room: Playroom) -> list[tuple[str, np.ndarray]]:
    """The hand takes the stick, whose tip then catches a toy beyond the hand's reach."""
    room.arrange(stick=(*HANDLE, 0.0), toys=np.vstack([TOY_ON_STICK_LINE, PARKED_TOYS[1:]]))
    waypoints = [
        Waypoint(16, tuple(HANDLE + (-0.03, 0.02)), 0.0),
        Waypoint(20, tuple(HANDLE + (-0.03, 0.02)), 0.0),
        Waypoint(34, tuple(HANDLE + (0.19, 0.01)), 0.0),
        Waypoint(50, (0.3, 0.35), 0.8),
    ]
    return [("arm", _command(waypoints))]


def _toy_scene(room: Playroom) -> list[tuple[str, np.ndarray]]:
    """The hand takes a toy and carries it; then the caregiver brings a toy while the agent
    speaks."""
    room.arrange(toys=np.vstack([TOY_IN_REACH, PARKED_TOYS[1:]]), caregiver=(-0.8, 0.6))
    carry = _command([Waypoint(25, tuple(TOY_IN_REACH)), Waypoint(50, (0.35, 0.0))])
    return [("arm", carry), (BRING, np.array(2)), ("voice", np.zeros(VOICE_DIM))]


def _random_scene(room: Playroom) -> list[tuple[str, np.ndarray]]:
    """Random movements of both kinds, as a trial's first iterations are."""
    rng = np.random.default_rng(3)
    return [
        (space, rng.uniform(-1, 1, ARM_DIM if space == "arm" else VOICE_DIM))
        for space in ("arm", "voice") * 12
    ]


def _played(scene, compiled: bool) -> tuple[Playroom, list]:
    room = Playroom("physical", seed=0, config=PROJECT)
    room.tracing = True
    if not compiled:
        use_oracle(room)
    feedbacks = []
    room.traces = []  # type: ignore[attr-defined]
    for space, m in scene(room):
        if space == BRING:
            room.caregiver.start_bringing(room.physics, int(m))
        else:
            feedbacks.append(room.act(space, m))
            room.traces.append(room.last_trace)  # type: ignore[attr-defined]
    return room, feedbacks


@pytest.mark.parametrize("scene", [_tool_scene, _toy_scene, _random_scene])
def test_compiled_steps_give_the_python_loops_numbers(scene):
    python_room, python_feedbacks = _played(scene, compiled=False)
    room, feedbacks = _played(scene, compiled=True)
    for expected, got in zip(python_feedbacks, feedbacks, strict=True):
        np.testing.assert_array_equal(got.s, expected.s)
        np.testing.assert_array_equal(got.positions, expected.positions)
        np.testing.assert_array_equal(got.sound, expected.sound)
        assert got.events == expected.events
    for expected, got in zip(python_room.traces, room.traces, strict=True):
        np.testing.assert_array_equal(got.qpos, expected.qpos)
        np.testing.assert_array_equal(got.mocap_pos, expected.mocap_pos)
    np.testing.assert_array_equal(room.get_state()["physics"], python_room.get_state()["physics"])
    np.testing.assert_array_equal(room.physics.data.ptr.qacc, python_room.physics.data.ptr.qacc)
    kinds = {kind for f in feedbacks for kind in f.kinds()}
    if scene is _tool_scene:  # the scene does what it is meant to
        assert {ev.STICK_GRASPED, ev.TOY_CAUGHT} <= kinds
    if scene is _toy_scene:
        assert ev.TOY_GRASPED in kinds
        assert any(e.kind == ev.TOY_MOVED and e.by == "caregiver" for e in feedbacks[1].events)


def test_contact_sensors_say_what_the_contact_list_says():
    room = use_oracle(Playroom("physical", seed=0, config=PROJECT))
    scene = _tool_scene(room)
    p = room.physics
    pairs = [(p.hand_geom, p.handle_geom)]
    pairs += [(p.hand_geom, g) for g in p.toy_geoms] + [(p.tip_geom, g) for g in p.toy_geoms]
    seen = []

    write = p.write_tracked_positions

    def compare(out: np.ndarray) -> None:  # after every control step of the oracle's loop
        write(out)
        step = len(seen) + 1
        listed = {tuple(sorted(pair)) for pair in p.touching_pairs().tolist()}
        expected = [tuple(sorted(pair)) in listed for pair in pairs]
        sensed = list(p.grasp_contacts() > 0)
        assert sensed == expected, f"step {step}: {dict(zip(GRASP_CONTACTS, sensed, strict=True))}"
        seen.append(sensed)

    p.write_tracked_positions = compare  # type: ignore[method-assign]
    for space, m in scene:
        room.act(space, m)
    touched = np.array(seen).any(axis=0)
    assert touched[0] and touched[4], "the scene touches the handle and a toy with the tip"


def test_a_model_without_the_grasp_sensors_is_refused(tmp_path: Path):
    xml = Path(playroom_xml()).read_text()
    start, end = xml.index("<sensor>"), xml.index("</sensor>") + len("</sensor>")
    path = tmp_path / "playroom.xml"
    path.write_text(xml[:start] + xml[end:])
    with pytest.raises(ValueError, match="no contact sensor named hand_stick"):
        PlayroomPhysics.load(path=path)


def test_the_sensors_switched_off_between_control_steps_are_back_on_after_them():
    room = Playroom("physical", seed=0, config=PROJECT)
    m = room.physics.model.ptr
    view = disable_flags_view(m)
    assert view is not None, "opt.disableflags not found in the model's memory"
    view[0] = SENSORS_OFF  # the view is the model's field
    assert m.opt.disableflags == SENSORS_OFF
    view[0] = 0
    for space, command in _random_scene(room)[:4]:
        room.act(space, command)
        assert m.opt.disableflags == 0


def test_positions_the_loop_cannot_write_in_place_are_refused():
    room = Playroom("physical", seed=0, config=PROJECT)
    positions = np.zeros((51, 5, 4))[:, :, :2]  # a strided view: rows not contiguous
    with pytest.raises(ValueError, match="C-contiguous"):
        room.physics.control_steps(0, np.zeros((50, 3)), None, positions, np.arange(4))


def _voice_after_an_arm_movement(compiled: bool, push_toy: bool) -> tuple[Playroom, object]:
    """An arm movement, then a voice movement in which the caregiver brings nothing; with
    `push_toy`, a toy is still sliding when the voice movement begins."""
    room = Playroom("physical", seed=0, config=PROJECT)
    if not compiled:
        use_oracle(room)
    room.act("arm", np.random.default_rng(5).uniform(-1, 1, ARM_DIM))
    if push_toy:
        room.physics.data.qvel[room.physics.object_dof[1, 0]] = 0.5
    computed = room.physics.control_steps_computed[0]
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    assert room.caregiver.bringing is None
    return room, (feedback, room.physics.control_steps_computed[0] - computed)


@pytest.mark.parametrize("push_toy", [False, True])
def test_a_voice_movement_at_rest_is_not_stepped_yet_ends_in_the_stepped_state(push_toy):
    python_room, (expected, _) = _voice_after_an_arm_movement(compiled=False, push_toy=push_toy)
    room, (got, computed) = _voice_after_an_arm_movement(compiled=True, push_toy=push_toy)
    np.testing.assert_array_equal(got.positions, expected.positions)
    np.testing.assert_array_equal(got.s, expected.s)
    assert got.events == expected.events
    d, python_d = room.physics.data.ptr, python_room.physics.data.ptr
    assert d.time == python_d.time  # 500 steps' time, whether stepped or not
    for field in ("qpos", "qvel", "qacc", "qacc_warmstart", "sensordata", "xpos", "site_xpos"):
        np.testing.assert_array_equal(getattr(d, field), getattr(python_d, field), err_msg=field)
    if push_toy:  # the toy slides (slower and slower) through the whole movement
        assert computed == 50
        assert not np.array_equal(got.positions[0, 2], got.positions[-1, 2])
    else:  # the arm's last push decays within the first steps; then nothing moves
        assert computed < 5
