"""A cheap stand-in world for the learner's tests and benchmarks. It is not the study's world.

It implements the `World` interface (models/world.py) with the layout of models/layout.py and
crude rules: a planar 3-link arm whose joint angles are a linear ramp to the end parameters
plus a few bumps; the hand picks up the stick or a toy that a sample passes within the grasp
distance of and carries it for the remaining samples; after an arm movement the caregiver says
the held toy's word or a random distractor; the voice is a fixed random nonlinear map to a 10D
sound, and a sound within the recognition distance of a toy's word brings that toy 40% of the
way to the caregiver's midpoint. Toys are placed anew every `replace_period` iterations. The
study's numbers (segment lengths, distances, period) are the caller's to give: the learner
does not own them (the world's configs do, in `sim`).
"""

from __future__ import annotations

import numpy as np

from models.layout import N_STEPS, SAMPLE_STEPS
from models.world import Feedback

SAMPLE_TIMES = np.array(SAMPLE_STEPS) / N_STEPS  # when objects are sampled, in movements


class SyntheticWorld:
    """A deterministic stand-in world (seeded), with the study's numbers given by the caller:
    segment_lengths (3,) m, grasp_distance m, recognition_distance (normalised sound units),
    replace_period iterations."""

    def __init__(
        self,
        seed: int,
        segment_lengths: tuple[float, float, float],
        grasp_distance: float,
        recognition_distance: float,
        replace_period: int,
    ) -> None:
        self.segments = np.asarray(segment_lengths, dtype=float)
        self.grasp_distance = float(grasp_distance)
        self.recognition_distance = float(recognition_distance)
        self.replace_period = int(replace_period)
        self.rng = np.random.default_rng(seed)
        self.words = self.rng.uniform(-0.8, 0.8, (6, 10))  # rows 0-2 name toys 1-3
        self._voice_map = self.rng.normal(0.0, 1.0, (10, 28)) / np.sqrt(28.0)
        self._handle = np.array([-0.25, 0.0])
        self._iteration = 0
        self._place_toys()
        self._caregiver = self.rng.uniform(-1.0, 1.0, 2)

    def context(self) -> np.ndarray:
        return np.concatenate((self._handle, self._toys.ravel(), self._caregiver))

    def act(self, motor_space: str, m: np.ndarray) -> Feedback:
        """Execute one command; return its feedback and move on to the next context."""
        toys = np.repeat(self._toys[:, None, :], 5, axis=1)  # (3 toys, 5 samples, xy)
        handle = np.repeat(self._handle[None, :], 5, axis=0)
        if motor_space == "arm":
            hand = self.hand(m)
            held: int | str | None = None  # a toy's index, or "stick"
            for k in range(5):
                if held is None:
                    if np.linalg.norm(hand[k] - self._handle) < self.grasp_distance:
                        held = "stick"
                    else:
                        near = np.linalg.norm(self._toys - hand[k], axis=1) < self.grasp_distance
                        held = int(np.argmax(near)) if near.any() else None
                if held == "stick":
                    handle[k:] = hand[k:]
                elif isinstance(held, int):
                    toys[held, k:] = hand[k:]
            word = held if isinstance(held, int) else int(self.rng.integers(3, 6))
            sound = self.words[word]
        else:
            hand = np.repeat(self.hand(np.zeros(21))[:1], 5, axis=0)
            sound = np.tanh(self._voice_map @ m)
            errors = np.linalg.norm(self.words[:3] - sound, axis=1)
            if errors.min() < self.recognition_distance:
                toy = int(np.argmin(errors))
                target = self._caregiver / 2.0
                toys[toy] += 0.4 * SAMPLE_TIMES[:, None] * (target - self._toys[toy])
        self._toys: np.ndarray = toys[:, -1].copy()
        self._handle = handle[-1].copy()
        s = np.concatenate(
            [_block(hand), _block(handle)] + [_block(toys[i]) for i in range(3)] + [sound]
        )
        self._iteration += 1
        if self._iteration % self.replace_period == 0:
            self._place_toys()
        self._caregiver = self.rng.uniform(-1.0, 1.0, 2)
        return Feedback(motor_space, s)

    def hand(self, m: np.ndarray) -> np.ndarray:
        """Hand positions (5, 2) at the sample times for arm parameters m (21,)."""
        params = m.reshape(3, 7)
        bumps = np.exp(-(((SAMPLE_TIMES[:, None] - np.linspace(0, 1, 6)) / 0.2) ** 2))
        angles = params[:, 6:7] * SAMPLE_TIMES + 0.3 * params[:, :6] @ bumps.T  # (3, 5)
        cumulative = np.cumsum(np.pi * np.clip(angles, -1.0, 1.0), axis=0) + np.pi / 2
        x = self.segments @ np.cos(cumulative)
        y = self.segments @ np.sin(cumulative)
        return np.stack((x, y), axis=1)

    def _place_toys(self) -> None:
        radius = self.rng.uniform(0.0, 1.0, 3)
        angle = self.rng.uniform(-np.pi, np.pi, 3)
        self._toys = np.stack((radius * np.cos(angle), radius * np.sin(angle)), axis=1)


def _block(samples: np.ndarray) -> np.ndarray:
    """(5, 2) samples -> (10,) laid out as 5 x then 5 y."""
    return samples.T.ravel()
