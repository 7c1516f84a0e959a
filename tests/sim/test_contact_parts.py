"""The contact step's parts, each a world setting of its own: touches sensed but
exerting no force (`unheld_contacts`), the caregiver's toy placed on her path rather than
welded to her hand (`caregiver_carrying`), the kinematic toys placed clear of each other and of
the stick (`placements_clear`). Each default is the room as it was."""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np
import pytest

from experiments.trial_dir.config_file import with_added_settings
from sim import Playroom
from sim import events as ev
from sim.arm_servo import ArmServo
from sim.config import world_preset
from sim.dmp import arm_trajectory
from sim.kinematics import hand_positions, segment_distance
from sim.mujoco_import import mujoco


def _scene(room: Playroom) -> None:
    """Toy 1 overlapping the resting hand, toy 2 overlapping toy 1, toy 3 on the stick's tip."""
    p = room.physics
    hand, tip = p.hand_position(), p.stick_tip()
    toys = np.array([hand + [0.05, 0.0], hand + [0.11, 0.0], tip + [0.04, 0.0]])
    room.arrange(toys=toys)


@pytest.mark.parametrize("contacts", ["solid", "sensed"])
def test_sensed_touches_are_found_where_solid_ones_are_and_none_exerts_a_force(contacts):
    room = Playroom("physical", seed=0, config=world_preset("study", unheld_contacts=contacts))
    _scene(room)
    m, d = room.physics.model.ptr, room.physics.data.ptr
    # hand on the handle, on toys 1-3, the tip on toys 1-3: the hand on toy 1, the tip on toy 3
    assert list(room.physics.grasp_contacts()) == [0, 1, 0, 0, 0, 0, 1]
    acting = d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_CONTACT_PYRAMIDAL
    assert acting.any() == (contacts == "solid")
    assert d.ncon >= 3 and m.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL


def _arm_commands(n: int, **world) -> tuple[int, Counter, Counter]:
    """n random arm commands of a physical room of seed 3: how many took nothing and yet left
    the hand more than 1 cm from where the servo arm alone goes, the events' kinds, and who
    moved an object."""
    config = world_preset("study", **world)
    room = Playroom("physical", seed=3, config=config)
    servo, rng = ArmServo(), np.random.default_rng(0)
    blocked, kinds, movers = 0, Counter(), Counter()
    for _ in range(n):
        command = rng.uniform(-1, 1, 21)
        feedback = room.act("arm", command)
        alone = hand_positions(servo.path(arm_trajectory(command, config)), config)
        took = any(e.kind in (ev.STICK_GRASPED, ev.TOY_GRASPED) for e in feedback.events)
        bent = np.linalg.norm(feedback.positions[:, 0] - alone, axis=1).max() > 0.01
        blocked += bool(bent and not took)
        kinds.update(e.kind for e in feedback.events)
        movers.update(e.by for e in feedback.events if e.kind in (ev.STICK_MOVED, ev.TOY_MOVED))
    return blocked, kinds, movers


def test_sensed_touches_take_what_they_touch_and_push_or_block_nothing():
    """The contact's reach alone: grasps and catches go on, nothing is pushed, and no movement
    that took nothing leaves the servo arm's own path (with solid, held-still objects one did,
    seed 3: the hand blocked)."""
    blocked, kinds, movers = _arm_commands(300, unheld_contacts="sensed")
    assert blocked == 0 and set(movers) <= {"hand", "stick"}
    assert kinds[ev.STICK_GRASPED] > 0 and kinds[ev.TOY_GRASPED] > 0 and kinds[ev.TOY_CAUGHT] > 0
    held_still, _, _ = _arm_commands(300, push_objects=False)
    assert held_still > 0


def test_what_a_world_of_sensed_touches_records_it_does_not_push():
    for contacts, pushes in (("solid", True), ("sensed", False)):
        room = Playroom("physical", config=world_preset("study", unheld_contacts=contacts))
        assert room.backend.capabilities()["pushes"] is pushes


def _brought_path(carrying: str) -> tuple[np.ndarray, np.ndarray, list]:
    """A vocal movement during which the caregiver brings toy 2: its positions at each step,
    her path, and the events."""
    room = Playroom("physical", seed=1, config=world_preset("study", caregiver_carrying=carrying))
    room.caregiver.start_bringing(room.physics, 1)
    path = room.caregiver.brought.path.copy()
    feedback = room.act("voice", np.zeros(28))
    return feedback.positions[:, 3], path, feedback.events


def test_a_placed_toy_is_on_her_path_at_every_step_where_a_welded_one_follows_her_hand():
    placed, path, events = _brought_path("placed")
    np.testing.assert_allclose(placed, path, atol=1e-12)
    welded, same_path, _ = _brought_path("welded")
    np.testing.assert_array_equal(path, same_path)
    lag = np.linalg.norm(welded - path, axis=1)
    assert lag.max() > 1e-4  # the weld is soft: the toy trails her hand
    assert [e.by for e in events if e.kind == ev.TOY_MOVED] == ["caregiver"]


def test_kinematic_placements_keep_clear_only_when_asked():
    """Over 200 placements of seed 0 the study's kinematic rules put a toy on the stick or on
    another toy; with placements_clear none is."""

    def overlaps(clear: bool) -> int:
        config = world_preset("study", placements_clear=clear)
        room = Playroom("kinematic", seed=0, config=config)
        p, gap, found = room.physics, room.min_toy_gap, 0
        for _ in range(200):
            room.experimenter.place_toys(room.rng)
            toys = p.toy_positions()
            near = room.experimenter.toy_radius + room.experimenter.stick_radius
            on_stick = [segment_distance(t, p.stick_handle(), p.stick_tip()) < near for t in toys]
            apart = [np.linalg.norm(toys[i] - toys[j]) for i in range(3) for j in range(i)]
            found += any(on_stick) or min(apart) < gap
        return found

    assert overlaps(False) > 0 and overlaps(True) == 0


@pytest.mark.parametrize(
    ("name", "value"),
    [("unheld_contacts", "solid"), ("caregiver_carrying", "welded"), ("placements_clear", False)],
)
def test_each_part_is_a_checked_setting_whose_older_trials_ran_its_default(name, value):
    with pytest.raises(ValueError, match=name):
        dataclasses.replace(world_preset("study"), **{name: "neither"})
    assert with_added_settings({"world": {"grasp_distance": 0.1}})["world"][name] == value
    assert getattr(world_preset("study"), name) == value
