"""The experimenter: who places the toys between iterations (docs/protocol.md §1) and, as the
project's smallest addition to the study, returns a stick that has left the agent's reach
(docs/protocol.md §11, "stick return").

In the study's kinematic world a dropped stick lies where the hand let it go, always within
reach. In the physical world a stick can be pushed, and pushes add up until it lies beyond any
reach for the rest of the trial, a situation the study never had. With `stick_return =
"out_of_reach"` (the default) the experimenter puts it back at its start pose at the end of an
iteration after which the backend's grasp rule can no longer reach its handle (`stick_lost`);
with "never" the stick stays where it is, as in the study's text.
"""

from __future__ import annotations

import numpy as np

from models.layout import N_STEPS, TOYS
from sim import events as ev
from sim.config import WorldConfig
from sim.grasping.base import GraspBackend
from sim.kinematics import segment_distance
from sim.physics import PlayroomPhysics

# Toys placed among solid objects (the physical backend) keep this clearance from each other and
# the stick (m): two solid objects cannot share a place, and overlapping geoms would be pushed
# apart violently.
PLACEMENT_CLEARANCE = 0.01


class Experimenter:
    """Places the toys of a room, and returns its stick when the config says so."""

    def __init__(
        self, config: WorldConfig, physics: PlayroomPhysics, backend: GraspBackend
    ) -> None:
        self.config = config
        self.physics = physics
        self.backend = backend
        # Placements keep clear of each other and of the stick: solid objects must; the
        # kinematic rules do where the world says so (WorldConfig.placements_clear).
        self.clear = backend.solid or config.placements_clear
        m = physics.model.ptr
        self.toy_radius = float(m.geom_size[physics.toy_geoms[0], 0])
        # The thickest part of the stick (its tip sphere), measured from the handle-tip line.
        self.stick_radius = float(m.geom_size[physics.stick_geoms, 0].max())

    @property
    def min_toy_gap(self) -> float:
        """Distance (m) between the centres of two toys placed side by side."""
        return 2 * self.toy_radius + PLACEMENT_CLEARANCE

    # Toys ---------------------------------------------------------------------------------
    def place_toys(self, rng: np.random.Generator) -> None:
        """Each toy picks one of the rings with equal chance, a uniform radius in it and a
        uniform angle (placed clear, `clear`: drawn again until clear of the others and of the
        stick)."""
        p = self.physics
        poses = p.object_poses()
        for i in range(len(TOYS)):
            while True:
                position = self._random_ring_position(rng)
                if not self.clear or self._toy_fits(position, poses, i):
                    break
            poses[1 + i] = (*position, 0.0)
        p.set_object_poses(poses)

    def _random_ring_position(self, rng: np.random.Generator) -> np.ndarray:
        rings = self.config.toy_rings
        low, high = rings[rng.integers(len(rings))]
        radius = rng.uniform(low, high)
        angle = rng.uniform(0.0, 2.0 * np.pi)
        return radius * np.array([np.cos(angle), np.sin(angle)])

    def _toy_fits(self, position: np.ndarray, poses: np.ndarray, toy: int) -> bool:
        """Whether a toy at `position` keeps clear of the toys placed before it and the stick."""
        for j in range(toy):
            if np.linalg.norm(position - poses[1 + j, :2]) < self.min_toy_gap:
                return False
        p = self.physics
        return self.clear_of_stick(position, p.stick_handle(), p.stick_tip())

    def clear_of_stick(self, position: np.ndarray, handle: np.ndarray, tip: np.ndarray) -> bool:
        """Whether a toy at `position` keeps PLACEMENT_CLEARANCE from a stick lying from
        `handle` to `tip` (its thickest part, the tip sphere, taken all along)."""
        clearance = self.toy_radius + self.stick_radius + PLACEMENT_CLEARANCE
        return segment_distance(position, handle, tip) >= clearance

    # The stick ----------------------------------------------------------------------------
    def stick_lost(self) -> bool:
        """Whether the backend's grasp rule can no longer reach the stick's handle (each
        backend says when: sim/grasping/)."""
        return self.backend.stick_out_of_reach(self.physics)

    def start_stick(self) -> tuple[np.ndarray, np.ndarray]:
        """(handle, tip) of the stick at its start pose (m)."""
        cfg = self.config
        handle = np.array(cfg.stick_start_handle)
        direction = np.array([np.cos(cfg.stick_start_angle), np.sin(cfg.stick_start_angle)])
        return handle, handle + cfg.stick_length * direction

    def return_stick_if_lost(self) -> list[ev.Event]:
        """With stick_return 'out_of_reach': a lost stick back at its start pose, if no toy
        lies there now (then at the end of a later iteration, the toys having moved)."""
        if self.config.stick_return != "out_of_reach" or not self.stick_lost():
            return []
        cfg, p = self.config, self.physics
        handle, tip = self.start_stick()
        toys = p.toy_positions()
        if self.clear and not all(self.clear_of_stick(t, handle, tip) for t in toys):
            return []
        poses = p.object_poses()
        poses[0] = (*cfg.stick_start_handle, cfg.stick_start_angle)
        p.set_object_poses(poses)
        return [ev.Event(ev.STICK_RETURNED, N_STEPS, obj="stick", by="experimenter")]
