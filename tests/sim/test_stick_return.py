"""The experimenter returns a stick that has left the hand's reach (sim/experimenter.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from models.layout import VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.config import DEFAULT_WORLD

FAR = (0.9, 0.1, 0.3)  # a handle 0.9 m from the base: beyond the arm (0.5) + grasp (0.1)
PARKED_TOYS = np.array([[-0.8, -0.8], [0.0, -0.9], [0.8, -0.8]])


def _room(grasp: str, rule: str) -> Playroom:
    config = dataclasses.replace(DEFAULT_WORLD, stick_return=rule)
    room = Playroom(grasp, seed=0, config=config)
    room.arrange(stick=FAR, toys=PARKED_TOYS)
    return room


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_a_stick_out_of_reach_is_back_at_its_start_before_the_next_context(grasp):
    room = _room(grasp, "out_of_reach")
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    returned = [e for e in feedback.events if e.kind == ev.STICK_RETURNED]
    assert len(returned) == 1 and returned[0].step == 50
    np.testing.assert_allclose(room.context()[:2], DEFAULT_WORLD.stick_start_handle, atol=1e-9)
    # What the agent sensed of that movement is the stick where it lay, far away.
    assert feedback.s[10] == pytest.approx(FAR[0], abs=1e-3)


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_with_never_the_stick_stays_lost(grasp):
    room = _room(grasp, "never")
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    assert ev.STICK_RETURNED not in feedback.kinds()
    np.testing.assert_allclose(room.context()[:2], FAR[:2], atol=1e-3)


def test_a_stick_within_reach_is_left_where_it_lies():
    room = _room("physical", "out_of_reach")
    room.arrange(stick=(0.45, 0.2, 0.0))  # 0.49 m away: within 0.6
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    assert ev.STICK_RETURNED not in feedback.kinds()
    np.testing.assert_allclose(room.context()[:2], (0.45, 0.2), atol=1e-3)


def test_a_toy_on_the_start_place_delays_the_return_in_the_physical_room():
    room = _room("physical", "out_of_reach")
    handle = np.array(DEFAULT_WORLD.stick_start_handle)
    room.arrange(toys=np.vstack([handle + (0.0, 0.1), PARKED_TOYS[1:]]))
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    assert ev.STICK_RETURNED not in feedback.kinds()
    np.testing.assert_allclose(room.context()[:2], FAR[:2], atol=1e-3)


def test_an_unknown_rule_is_refused():
    # Refused where the config is built, before any room is made with it.
    with pytest.raises(ValueError, match="stick_return must be one of 'never', 'out_of_reach'"):
        dataclasses.replace(DEFAULT_WORLD, stick_return="sometimes")


# A handle 0.53 m from the base, the stick pointing outward: its handle geom lies within the
# contact limit (0.546 m), so only a `stick_return_reach` nearer than 0.53 m returns it.
NEAR_LIMIT = (0.53, 0.0, 0.0)


@pytest.mark.parametrize(("reach", "returned"), [(None, False), (0.54, False), (0.52, True)])
def test_the_physical_return_reach_is_a_setting(reach, returned):
    config = dataclasses.replace(DEFAULT_WORLD, stick_return_reach=reach)
    room = Playroom("physical", seed=0, config=config)
    room.arrange(stick=NEAR_LIMIT, toys=PARKED_TOYS)
    feedback = room.act("voice", np.zeros(VOICE_DIM))
    assert (ev.STICK_RETURNED in feedback.kinds()) == returned
    where = DEFAULT_WORLD.stick_start_handle if returned else NEAR_LIMIT[:2]
    np.testing.assert_allclose(room.context()[:2], where, atol=1e-3)


# Without a return reach, the handle geom (0.07 m from the handle's end along the stick) is out
# of reach when its nearest point lies beyond the contact limit (0.546 m): sticks pointing
# back at the base, whose handle's centre or end is the nearest point, and outward.
@pytest.mark.parametrize(
    ("handle_x", "angle", "lost"),
    [
        (0.56, np.pi, False),  # spans 0.49-0.56 m: its centre is within the limit
        (0.60, np.pi, False),  # spans 0.53-0.60 m: its centre is not, its near end is
        (0.63, np.pi, True),  # spans 0.56-0.63 m
        (0.53, 0.0, False),
        (0.55, 0.0, True),
    ],
)
def test_the_physical_contact_limit_is_the_handle_geoms_nearest_point(handle_x, angle, lost):
    config = dataclasses.replace(DEFAULT_WORLD, stick_return_reach=None)
    room = Playroom("physical", seed=0, config=config)
    room.arrange(stick=(handle_x, 0.0, angle), toys=PARKED_TOYS)
    assert room.backend.stick_out_of_reach(room.physics) == lost
