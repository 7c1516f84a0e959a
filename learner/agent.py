"""The Model Babbling agent (docs/protocol.md §9): bootstrap, goals, imitation, learning.

One iteration is `agent.play(world)`: `proposal = agent.propose(context)`, the world executes
`proposal.m` with the arm or the voice, then `agent.learn(proposal, context, s)` with the
feedback s (60,).

- Bootstrap: the first `bootstrap_arm + bootstrap_voice` proposals are uniformly random
  commands, their motor spaces in a shuffled order drawn at construction.
- Then: choose a model (learner.interest), a goal uniform in [goal_low, goal_high]^10 of its
  sensory space (for model 10, with probability `imitation_share`, a caregiver sound heard
  after one of the last `imitation_memory` arm movements instead), take the inverse model's
  command and add Gaussian noise of `exploration_sigma`, clipped to the motor bounds. A model
  with no experience yet proposes a uniformly random command (`inferred` is then False).
- Learning: every model of the motor space used applies the storing rule (cross-learning);
  the chosen model's interest records its competence; after an arm movement the sound block
  is recorded as a heard caregiver sound.

All randomness comes from the agent's own numpy Generator, which `state_dict` saves, so an
agent restored from a checkpoint continues bit-identically.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from learner.config import LearnerConfig, learner_preset
from learner.interest import InterestModel
from learner.sensorimotor_model import SensorimotorModel
from learner.storing_rule import changed_blocks
from models.layout import (
    BLOCK_DIM,
    CONTEXT_DIM,
    MODELS,
    MOTOR_DIMS,
    SENSORY_BLOCKS,
    SENSORY_DIM,
    ModelSpec,
    block_slice,
)
from models.presets import DEFAULT_PRESET
from models.world import Feedback, World

_SPACE_CODE = {"arm": 0, "voice": 1}  # bootstrap order is stored as these codes


@dataclass(frozen=True)
class Proposal:
    """What the agent wants to do this iteration."""

    motor_space: str  # "arm" or "voice"
    m: np.ndarray  # (21,) or (28,), in [motor_low, motor_high]
    model: int | None  # 0-based index into the model table; None during bootstrap
    goal: np.ndarray | None  # (10,) sensory goal of that model; None during bootstrap
    kind: str  # "bootstrap", "goal" (self-generated) or "imitation" (a caregiver sound)
    inferred: bool  # False when m is random (bootstrap, or a model with no experience yet)


class Agent:
    """Model Babbling over the models of `models` (default: the study's 10), with the learner
    `config` (default: the default preset's, `learner_preset(DEFAULT_PRESET)`)."""

    def __init__(
        self,
        config: LearnerConfig | None = None,
        rng: np.random.Generator | int | None = None,
        models: tuple[ModelSpec, ...] = MODELS,
    ) -> None:
        self.config = config if config is not None else learner_preset(DEFAULT_PRESET)
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        self.specs = tuple(models)
        self.models = [SensorimotorModel(spec, self.config) for spec in self.specs]
        self._by_space = {
            space: [k for k, spec in enumerate(self.specs) if spec.motor_space == space]
            for space in _SPACE_CODE
        }
        self._block_of = [SENSORY_BLOCKS.index(spec.sensory_block) for spec in self.specs]
        self.interest = InterestModel(len(self.specs), self.config)
        cfg = self.config
        if cfg.bootstrap == "coin_not_learned":  # each command arm or voice, a coin's toss
            self._bootstrap_order = (self.rng.random(cfg.n_bootstrap) < 0.5).astype(np.int8)
        else:
            order = [cfg.bootstrap_arm, cfg.bootstrap_voice]
            self._bootstrap_order = self.rng.permutation(
                np.repeat(np.array([0, 1], np.int8), order)
            )
        self.t = 0  # iterations learnt
        # Ring buffer of the sounds heard after the last `imitation_memory` arm movements.
        self._heard = np.zeros((cfg.imitation_memory, BLOCK_DIM))
        self._n_heard = 0
        # Every distinct caregiver sound heard so far (the "all_heard" imitation pool).
        self._distinct_heard = np.zeros((0, BLOCK_DIM))
        self._distinct_keys: set[tuple[float, ...]] = set()  # its rows, to look them up
        self._sound_slice = block_slice("sound")
        self._pending: Proposal | None = None

    # ------------------------------------------------------------------ the learning loop

    def propose(self, context: ArrayLike) -> Proposal:
        """The command to execute in `context` (10,)."""
        return self._propose(self._check_context(context))

    def _propose(self, context: np.ndarray) -> Proposal:
        """`propose`, with a context already checked."""
        cfg = self.config
        if self.t < cfg.n_bootstrap:
            space = "arm" if self._bootstrap_order[self.t] == 0 else "voice"
            m = self.rng.uniform(cfg.motor_low, cfg.motor_high, MOTOR_DIMS[space])
            proposal = Proposal(space, m, None, None, "bootstrap", False)
        else:
            k = self.interest.choose(self.rng)
            spec, model = self.specs[k], self.models[k]
            kind = "goal"
            if (
                spec.imitates_caregiver
                and self._n_heard > 0
                and self.rng.random() < cfg.imitation_share
            ):
                goal, kind = self._imitation_goal(), "imitation"
            else:
                goal = self.rng.uniform(cfg.goal_low, cfg.goal_high, model.sensory_dim)
            if model.outcomes < cfg.outcomes_to_infer:
                m = self.rng.uniform(cfg.motor_low, cfg.motor_high, model.motor_dim)
                inferred = False
            else:
                m = model.inverse_command(context, goal)
                m += self.rng.normal(0.0, cfg.exploration_sigma, model.motor_dim)
                # np.clip's values, in place, without its Python wrapper (every iteration).
                np.minimum(np.maximum(m, cfg.motor_low, out=m), cfg.motor_high, out=m)
                inferred = True
            proposal = Proposal(spec.motor_space, m, k, goal, kind, inferred)
        self._pending = proposal
        return proposal

    def play(
        self, world: World, act: Callable[[Proposal], Feedback] | None = None
    ) -> tuple[Proposal, np.ndarray, Feedback]:
        """One iteration in `world`: observe the context, propose, act, learn.

        act: how the proposal is executed, by default `world.act(motor_space, m)`; a caller
        that films the movement passes its own. Returns (proposal, context, feedback).
        """
        context = self._check_context(world.context())
        proposal = self._propose(context)
        if act is None:
            feedback = world.act(proposal.motor_space, proposal.m)
        else:
            feedback = act(proposal)
        self._learn(proposal, context, feedback.s)  # the context was checked above
        return proposal, context, feedback

    def learn(self, proposal: Proposal, context: ArrayLike, s: ArrayLike) -> None:
        """Learn from the feedback s (60,) of `proposal`, executed in `context` (10,)."""
        self._learn(proposal, self._check_context(context), s)

    def _learn(self, proposal: Proposal, context: np.ndarray, s: ArrayLike) -> None:
        """`learn`, with a context already checked."""
        if proposal is not self._pending:
            raise ValueError("learn() takes the proposal returned by the last propose()")
        s = _checked_vector(s, SENSORY_DIM, "feedback s")
        cfg = self.config
        if proposal.kind == "bootstrap" and cfg.bootstrap == "coin_not_learned":
            self.t += 1  # the study's published runs learned nothing from the bootstrap
            self._pending = None
            return
        if cfg.clip_sensory:
            s = _unit_clipped(s)
        m = proposal.m
        changed = changed_blocks(context, s, cfg.change_tolerance, cfg.storing_rule)
        for k in self._by_space[proposal.motor_space]:
            if changed[self._block_of[k]]:
                self.models[k].store(m, context, s)
        if proposal.model is not None:
            assert proposal.goal is not None  # propose() gives every model's proposal a goal
            reached = s[self.models[proposal.model].sensory_slice]  # `outcome`, s clipped above
            self.interest.update(proposal.model, proposal.goal, reached)
        if proposal.motor_space == "arm":
            sound = s[self._sound_slice]
            if np.logical_or.reduce(np.abs(sound) > cfg.change_tolerance):  # she spoke
                self._hear(sound)
        self.t += 1
        self._pending = None

    def outcome(self, proposal: Proposal, s: ArrayLike) -> np.ndarray | None:
        """What `proposal` reached (10,): the sensory block of its model (the block its goal
        lies in) in the feedback s (60,), as the learner reads it (clipped to [-1, 1] under
        `clip_sensory`); its competence is -|goal - outcome|. None for a proposal without a
        model (bootstrap: random motor babbling)."""
        if proposal.model is None:
            return None
        s = np.asarray(s, dtype=np.float64)
        if self.config.clip_sensory:
            s = _unit_clipped(s)
        return s[self.models[proposal.model].sensory_slice].copy()

    def interests(self) -> np.ndarray:
        """Each model's interest (n_models,): its learning progress (learner.interest), from
        which the next model is chosen under active babbling (kept under random babbling
        too, where it chooses nothing)."""
        return self.interest.progress()

    # ------------------------------------------------------------------ evaluation

    def toy_models(self, toy: int) -> tuple[int, int]:
        """0-based indices of the arm model and the voice model of toy 1, 2 or 3."""
        block = f"toy{toy}"
        found = {
            spec.motor_space: k for k, spec in enumerate(self.specs) if spec.sensory_block == block
        }
        if set(found) != {"arm", "voice"}:
            raise ValueError(f"no arm and voice models for toy {toy!r}")
        return found["arm"], found["voice"]

    def nearest_distance(self, model: int, context: ArrayLike, goal: ArrayLike) -> float:
        """Distance from (c_i, goal) to model's nearest experience (inf if it has none)."""
        return self.models[model].nearest_distance(self._check_context(context), goal)

    def exploit(self, model: int, context: ArrayLike, goal: ArrayLike) -> np.ndarray:
        """The inverse model's command for goal (10,) in context (10,), without noise.

        A model with no experience raises ValueError. Draws nothing from the agent's rng.
        """
        m, _ = self.models[model].inverse(self._check_context(context), goal)
        return m

    @property
    def heard_sounds(self) -> np.ndarray:
        """The caregiver sounds imitation draws from (k, 10), oldest first, k <= 100."""
        size = len(self._heard)
        if self._n_heard <= size:
            return self._heard[: self._n_heard].copy()
        start = self._n_heard % size
        return np.concatenate((self._heard[start:], self._heard[:start]))

    # ------------------------------------------------------------------ checkpoints

    def state_dict(self, rows_from: dict[int, int] | None = None) -> dict[str, np.ndarray]:
        """Everything to continue bit-identically: plain arrays and 0-d arrays, for np.savez.

        Keys: 'config' and 'rng' (JSON strings), 't', 'bootstrap_order', 'heard', 'n_heard',
        'interest.*', and 'model{number}.motor' / 'model{number}.key' per model: its rows
        from row `rows_from[number]` on (all of them by default). The rows are only ever
        appended: a trial's checkpoint stores those its earlier ones did not, apart
        (`memory_rows`), and its own rows from there on, none; `load_state_dict` takes every
        row back.
        """
        state: dict[str, np.ndarray] = {
            "config": np.array(self.config.to_json()),
            "models": np.array([spec.number for spec in self.specs]),
            "rng": np.array(json.dumps(_jsonable(self.rng.bit_generator.state))),
            "t": np.array(self.t, dtype=np.int64),
            "bootstrap_order": self._bootstrap_order.copy(),
            "heard": self._heard.copy(),
            "n_heard": np.array(self._n_heard, dtype=np.int64),
            "distinct_heard": self._distinct_heard.copy(),
        }
        for key, value in self.interest.state_dict().items():
            state[f"interest.{key}"] = value
        state.update(self.memory_rows(rows_from or {}))
        return state

    def memory_sizes(self) -> dict[int, int]:
        """The rows each model has stored, by model number."""
        return {
            spec.number: len(model) for spec, model in zip(self.specs, self.models, strict=True)
        }

    def memory_rows(self, rows_from: dict[int, int]) -> dict[str, np.ndarray]:
        """Each model's rows from row `rows_from[number]` on (0 for a model not named), under
        the keys of `state_dict`: 'model{number}.motor' and 'model{number}.key'."""
        rows = {}
        for spec, model in zip(self.specs, self.models, strict=True):
            for key, value in model.state_dict(rows_from.get(spec.number, 0)).items():
                rows[f"model{spec.number}.{key}"] = value
        return rows

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore a `state_dict()` (also as loaded by np.load). The config must match."""
        saved = json.loads(str(np.asarray(state["config"])))
        if saved != self.config.to_dict():
            diff = sorted(k for k in saved if saved.get(k) != self.config.to_dict().get(k))
            raise ValueError(f"checkpoint was made with another learner config: {diff}")
        numbers = [int(n) for n in np.asarray(state["models"])]
        if numbers != [spec.number for spec in self.specs]:
            raise ValueError(f"checkpoint has models {numbers}, this agent has other models")
        order = np.asarray(state["bootstrap_order"], dtype=np.int8)
        if order.shape != self._bootstrap_order.shape:
            raise ValueError(f"checkpoint bootstrap order has shape {order.shape}")
        heard = np.asarray(state["heard"], dtype=np.float64)
        if heard.shape != self._heard.shape:
            raise ValueError(f"checkpoint heard sounds have shape {heard.shape}")
        for spec, model in zip(self.specs, self.models, strict=True):
            prefix = f"model{spec.number}."
            model.load_state_dict(
                {k[len(prefix) :]: v for k, v in state.items() if k.startswith(prefix)}
            )
        self.interest.load_state_dict(
            {k[len("interest.") :]: v for k, v in state.items() if k.startswith("interest.")}
        )
        self.rng.bit_generator.state = json.loads(str(np.asarray(state["rng"])))
        self.t = int(state["t"])
        self._bootstrap_order = order.copy()
        self._heard = heard.copy()
        self._n_heard = int(state["n_heard"])
        distinct = np.asarray(state.get("distinct_heard", np.zeros((0, BLOCK_DIM))), float)
        self._distinct_heard = distinct.reshape(-1, BLOCK_DIM).copy()
        self._distinct_keys = {tuple(row) for row in self._distinct_heard.tolist()}
        self._pending = None

    # ------------------------------------------------------------------ helpers

    def _hear(self, sound: np.ndarray) -> None:
        """Remember a caregiver sound: in the ring buffer of recent sounds, or, with the
        "all_heard" pool, among the distinct sounds heard so far (never forgotten)."""
        if self.config.imitation_pool == "all_heard":
            # As tuples of Python floats, rows compare as NumPy's == does (0.0 == -0.0).
            key = tuple(sound.tolist())
            if key not in self._distinct_keys:
                self._distinct_keys.add(key)
                self._distinct_heard = np.vstack([self._distinct_heard, sound])
        self._heard[self._n_heard % len(self._heard)] = sound
        self._n_heard += 1

    def _imitation_goal(self) -> np.ndarray:
        if self.config.imitation_pool == "all_heard":  # in the order first heard
            return self._distinct_heard[self.rng.integers(len(self._distinct_heard))].copy()
        sounds = self.heard_sounds
        if self.config.imitation_draw == "distinct":
            sounds = np.unique(sounds, axis=0)  # sorted: the draw does not depend on order
        return sounds[self.rng.integers(len(sounds))].copy()

    def _check_context(self, context: ArrayLike) -> np.ndarray:
        return _checked_vector(context, CONTEXT_DIM, "context")


def _unit_clipped(v: np.ndarray) -> np.ndarray:
    """v.clip(-1, 1)'s values, without its Python wrapper (twice every iteration)."""
    return np.minimum(np.maximum(v, -1.0), 1.0)


def _checked_vector(value: ArrayLike, dim: int, what: str) -> np.ndarray:
    """`value` as a finite float64 vector of shape (dim,), or ValueError naming `what`."""
    vector = np.asarray(value, dtype=np.float64)
    if vector.shape != (dim,):
        raise ValueError(f"{what} must have shape ({dim},), got {vector.shape}")
    # ndarray.all()'s answer without its Python wrapper (three times every iteration).
    if not np.logical_and.reduce(np.isfinite(vector)):
        raise ValueError(f"{what} has a NaN or infinite value")
    return vector


def _jsonable(value: Any) -> Any:
    """The bit generator's state with numpy scalars and arrays made JSON-friendly."""
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.integer):
        return int(value)
    return value
