"""`playroom rl-behaviour` counts what an actor does on a goal environment's episodes: the
voice's share (a[0] >= 0), the goal toy moved (its achieved goal changed) and the goal reached
(reward 0), per movement; and refuses in one line where there is no run."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.baseline.behaviour import FIRST_EPISODE_SEED, run_behaviour, tally
from experiments.baseline.settings import BaselineError
from experiments.cli.main import main


class _ThreeMovements:
    """A goal environment's shape: episodes of 3 movements; the toy moves when a[1] > 0, and
    the goal is reached when a[2] > 0. Remembers the seeds it was reset with."""

    def __init__(self) -> None:
        self.seeds: list[int] = []

    def reset(self, seed: int):
        self.seeds.append(seed)
        self.toy, self.step_count = np.zeros(2), 0
        return {"achieved_goal": self.toy.copy()}, {}

    def step(self, action):
        self.step_count += 1
        if action[1] > 0:
            self.toy = self.toy + 0.1
        reward = 0.0 if action[2] > 0 else -1.0
        return {"achieved_goal": self.toy.copy()}, reward, False, self.step_count == 3, {}


def test_an_actors_movements_are_counted_as_defined():
    env = _ThreeMovements()
    actions = iter(
        [[1, 1, 1], [-1, 0, 0], [0, -1, 1]]  # voice, moved, reached; arm; voice (a[0] = 0), reached
        + [[-1, -1, -1], [-1, 1, -1], [-1, -1, -1]]  # arm thrice, one move, nothing reached
    )
    n, voice, moved, reached = tally(env, lambda _: np.array(next(actions), float), episodes=2)  # type: ignore[arg-type]
    assert n == 6
    assert (voice, moved, reached) == pytest.approx((2 / 6, 2 / 6, 2 / 6))
    assert env.seeds == [FIRST_EPISODE_SEED, FIRST_EPISODE_SEED + 1]  # the same rooms each time


def test_a_folder_without_a_run_is_refused_in_one_line(tmp_path, capsys):
    with pytest.raises(BaselineError, match="holds no baseline run"):
        run_behaviour(tmp_path, episodes=1)
    assert main(["rl-behaviour", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds no run of playroom rl-baseline" in err[0]
