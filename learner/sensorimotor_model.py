"""Sensorimotor models: one arrow of the paper's Fig. 2, motor space -> sensory block | context.

A model keeps the experiences (m, c_i, s_i) of its motor space whose sensory block changed,
and answers, by nearest neighbour (docs/protocol.md §8):
- inverse: the motor command m of the stored (c_i, s_i) nearest to (context, goal);
- forward: the sensory block s_i of the stored (m, c_i) nearest to (command, context).

A model stores an experience when its own sensory block changed, by the storing rule of
learner/storing_rule.py (the paper's, or the study's code's: docs/protocol.md §11).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from learner.config import LearnerConfig
from learner.memory import NearestNeighbourMemory
from learner.storing_rule import changed_blocks
from models.layout import BLOCK_DIM, MODELS, MOTOR_DIMS, SENSORY_BLOCKS, ModelSpec

__all__ = ["MODELS", "ModelSpec", "SensorimotorModel"]

_INITIAL_CAPACITY = 1024  # rows preallocated per model, doubled when full


class SensorimotorModel:
    """The experiences of one ModelSpec, with nearest-neighbour inverse and forward models."""

    def __init__(self, spec: ModelSpec, config: LearnerConfig) -> None:
        self.spec = spec  # a ModelSpec checks its own spaces, block and slots
        self.motor_dim = MOTOR_DIMS[spec.motor_space]
        self.context_dims = np.array(spec.context_dims, dtype=np.intp)
        self.sensory_slice = spec.sensory_slice
        self.sensory_dim = BLOCK_DIM
        self._tolerance = config.change_tolerance
        self._rule = config.storing_rule
        self._block = SENSORY_BLOCKS.index(spec.sensory_block)
        self.outcomes = 0  # different sensory outcomes stored, counted up to 2
        c_dim = len(self.context_dims)
        self._motor = np.empty((_INITIAL_CAPACITY, self.motor_dim))
        self._n = 0
        self._inverse = NearestNeighbourMemory(c_dim + self.sensory_dim)  # rows (c_i, s_i)
        self._forward: NearestNeighbourMemory | None = None  # rows (m, c_i), built on demand

    def __len__(self) -> int:
        return self._n

    @property
    def motor(self) -> np.ndarray:
        """Stored motor commands (n, motor_dim), read-only view."""
        view = self._motor[: self._n]
        view.flags.writeable = False
        return view

    @property
    def context(self) -> np.ndarray:
        """Stored contexts c_i (n, len(context_dims)), read-only view."""
        return self._inverse.rows[:, : len(self.context_dims)]

    @property
    def sensory(self) -> np.ndarray:
        """Stored sensory blocks s_i (n, 10), read-only view."""
        return self._inverse.rows[:, len(self.context_dims) :]

    def sensory_changed(self, context: np.ndarray, s: np.ndarray) -> bool:
        """The storing rule (learner/storing_rule.py) for a context (10,) and feedback (60,)."""
        changed = changed_blocks(context, s, self._tolerance, self._rule)
        return bool(changed[self._block])

    def update(self, m: np.ndarray, context: np.ndarray, s: np.ndarray) -> bool:
        """Store (m, c_i, s_i) if the sensory block changed; return whether it was stored.

        m (motor_dim,), context (10,), s (60,): the caller has checked shapes.
        """
        if not self.sensory_changed(context, s):
            return False
        self.store(m, context, s)
        return True

    def store(self, m: np.ndarray, context: np.ndarray, s: np.ndarray) -> None:
        """Store (m, c_i, s_i) without the storing rule, from checked, finite vectors."""
        c_i = context[self.context_dims]
        self._count_outcome(s[self.sensory_slice])
        self._inverse.append(np.concatenate((c_i, s[self.sensory_slice])), checked=True)
        if self._n == len(self._motor):  # full: grown by the general path
            self._append_motor(m[None, :])
        else:  # _append_motor's effect for one row, every iteration
            self._motor[self._n] = m
            self._n += 1
        if self._forward is not None:
            self._forward.append(np.concatenate((m, c_i)), checked=True)

    def extend(self, motor: ArrayLike, context: ArrayLike, sensory: ArrayLike) -> None:
        """Store k experiences at once, without the storing rule (loading, benchmarks).

        motor (k, motor_dim), context (k, len(context_dims)) already reduced to c_i,
        sensory (k, 10) already reduced to s_i.
        """
        motor = np.asarray(motor, dtype=np.float64)
        context = np.asarray(context, dtype=np.float64).reshape(len(motor), -1)
        sensory = np.asarray(sensory, dtype=np.float64)
        if motor.ndim != 2 or motor.shape[1] != self.motor_dim:
            raise ValueError(f"motor rows must have shape (k, {self.motor_dim}), got {motor.shape}")
        if context.shape[1] != len(self.context_dims) or sensory.shape != (
            len(motor),
            self.sensory_dim,
        ):
            raise ValueError(
                f"model {self.spec.number}: context (k, {len(self.context_dims)}) and sensory "
                f"(k, {self.sensory_dim}) rows expected, got {context.shape}, {sensory.shape}"
            )
        if not np.isfinite(motor).all():
            raise ValueError("motor rows have a NaN or infinite value")
        self._inverse.extend(np.hstack((context, sensory)))
        self._recount_outcomes()
        self._append_motor(motor)
        if self._forward is not None:
            self._forward.extend(np.hstack((motor, context)))

    def _count_outcome(self, block: np.ndarray) -> None:
        """Count a newly stored sensory block towards `outcomes` (1, or 2 once one differs
        from the first stored)."""
        if self.outcomes == 0:
            self.outcomes = 1
        elif self.outcomes == 1 and not np.array_equal(block, self.sensory[0]):
            self.outcomes = 2

    def _recount_outcomes(self) -> None:
        sensory = self.sensory
        if len(sensory) == 0:
            self.outcomes = 0
        else:
            self.outcomes = 2 if (sensory != sensory[0]).any() else 1

    def inverse(self, context: np.ndarray, goal: ArrayLike) -> tuple[np.ndarray, float]:
        """(motor command (motor_dim,) of the stored (c_i, s_i) nearest to (c_i, goal), distance).

        context (10,) full context, goal (10,). Raises ValueError if the model is empty.
        """
        i, distance = self._nearest_inverse(context, goal)
        return self._motor[i].copy(), distance

    def nearest_experience(
        self, context: np.ndarray, goal: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """The stored experience `inverse` would replay: (motor command, its context c_i, its
        sensory block s_i, distance from (c_i, goal)), copies. ValueError if empty."""
        i, distance = self._nearest_inverse(context, goal)
        return self._motor[i].copy(), self.context[i].copy(), self.sensory[i].copy(), distance

    def inverse_command(self, context: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """`inverse`'s command alone, without computing the distance (the learning loop's
        query), from a checked context (10,) and a float64 goal (10,)."""
        if self._n == 0:
            raise ValueError(f"model {self.spec.number} has no experience to invert")
        key = np.concatenate((context[self.context_dims], goal))
        return self._motor[self._inverse.nearest_index(key)].copy()

    def nearest_distance(self, context: np.ndarray, goal: ArrayLike) -> float:
        """Euclidean distance from (c_i, goal) to the nearest stored (c_i, s_i); inf if empty."""
        if self._n == 0:
            return float("inf")
        return self._nearest_inverse(context, goal)[1]

    def forward(self, m: np.ndarray, context: np.ndarray) -> np.ndarray:
        """Predicted sensory block (10,): s_i of the stored (m, c_i) nearest to (m, c_i)."""
        if self._n == 0:
            raise ValueError(f"model {self.spec.number} has no experience to predict from")
        m = np.asarray(m, dtype=np.float64)
        if m.shape != (self.motor_dim,):
            raise ValueError(f"motor command must have shape ({self.motor_dim},), got {m.shape}")
        if self._forward is None:
            # Built on the first forward question only: the learning loop never asks one.
            self._forward = NearestNeighbourMemory(self.motor_dim + len(self.context_dims))
            self._forward.extend(np.hstack((self.motor, self.context)))
        c_i = np.asarray(context, dtype=np.float64)[self.context_dims]
        i, _ = self._forward.nearest(np.concatenate((m, c_i)))
        return self.sensory[i].copy()

    def state_dict(self, start: int = 0) -> dict[str, np.ndarray]:
        """{'motor': (n - start, motor_dim), 'key': (n - start, c_dim + 10)}: the rows stored
        from row `start` on (all of them by default), plain float64 copies. Rows are only ever
        appended, so a checkpoint writes each once: those stored since the last one
        (experiments/run/memory_segments.py)."""
        return {
            "motor": self._motor[start : self._n].copy(),
            "key": self._inverse.rows[start:].copy(),
        }

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        motor = np.asarray(state["motor"], dtype=np.float64)
        key = np.asarray(state["key"], dtype=np.float64)
        if motor.ndim != 2 or motor.shape[1] != self.motor_dim or key.shape[0] != len(motor):
            raise ValueError(
                f"model {self.spec.number}: state of {motor.shape} motor rows and {key.shape} "
                f"keys does not fit motor dimension {self.motor_dim}"
            )
        self._inverse.load_state_dict({"rows": key})
        self._recount_outcomes()
        self._motor = np.empty((_INITIAL_CAPACITY, self.motor_dim))
        self._n = 0
        self._append_motor(motor)
        self._forward = None

    def nbytes(self) -> int:
        """Bytes held by this model's arrays."""
        forward = 0 if self._forward is None else self._forward.nbytes()
        return self._motor.nbytes + self._inverse.nbytes() + forward

    def _nearest_inverse(self, context: np.ndarray, goal: ArrayLike) -> tuple[int, float]:
        if self._n == 0:
            raise ValueError(f"model {self.spec.number} has no experience to invert")
        goal = np.asarray(goal, dtype=np.float64)
        if goal.shape != (self.sensory_dim,):
            raise ValueError(f"goal must have shape ({self.sensory_dim},), got {goal.shape}")
        c_i = np.asarray(context, dtype=np.float64)[self.context_dims]
        return self._inverse.nearest(np.concatenate((c_i, goal)))

    def _append_motor(self, motor: np.ndarray) -> None:
        k = len(motor)
        if self._n + k > len(self._motor):
            capacity = max(len(self._motor), _INITIAL_CAPACITY)
            while capacity < self._n + k:  # doubling, as the memories grow
                capacity *= 2
            grown = np.empty((capacity, self.motor_dim))
            grown[: self._n] = self._motor[: self._n]
            self._motor = grown
        self._motor[self._n : self._n + k] = motor
        self._n += k
