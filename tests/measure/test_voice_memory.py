"""What the voice's toy models remember (experiments/measure/voice_memory.py): the
commands stored are told apart by what the caregiver hears in them."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.measure.voice_memory import toy_model_rows
from learner.agent import Agent
from learner.config import LearnerConfig
from models.layout import VOICE_DIM
from sim import Playroom
from sim.config import world_preset
from sim.vocal.vtl.productions import say


def test_the_stored_commands_are_sorted_by_what_the_caregiver_hears():
    room = Playroom("kinematic", seed=0, config=world_preset("project"))  # say()'s DMP
    agent = Agent(LearnerConfig(), rng=0)
    names = room.caregiver.words.names
    other = next(w for w in room.vocal_tract.config.words if w != names[0])
    _, voice_model = agent.toy_models(1)
    # Toy 1's model: its name said (a bring), another word, silence-like nonsense (a nudge).
    motor = np.stack([say(names[0]), say(other), np.zeros(VOICE_DIM)])
    context = np.zeros((3, 4))  # the toy and the caregiver
    start = np.r_[np.full(5, 0.4), np.full(5, 0.0)]
    brought = np.r_[np.linspace(0.4, 0.1, 5), np.zeros(5)]
    agent.models[voice_model].extend(motor, context, np.stack([brought, brought, start]))
    table = toy_model_rows(agent, room).set_index("toy")
    assert table.loc[1, "rows"] == 3
    assert table.loc[1, "name"] == pytest.approx(1 / 3)
    assert table.loc[1, "other_word"] == pytest.approx(1 / 3)
    assert table.loc[1, "no_word"] == pytest.approx(1 / 3)
    assert table.loc[1, "nudged"] == pytest.approx(1 / 3)
    assert table.loc[2, "rows"] == 0 and np.isnan(table.loc[2, "name"])
