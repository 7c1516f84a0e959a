"""Which model to train next: uniformly at random, or by learning progress.

Competence of an attempt: minus the Euclidean distance between the goal and the sensory block
reached (both (10,)), so 0 is perfect and -2 sqrt(10) is the worst in [-1, 1]^10.

Progress measure ("active" model babbling): for each model, the competences of its last
2 W attempts (W = `progress_window`) are kept; its progress is

    | mean(competence of the newest W attempts) - mean(competence of the W before them) |

the absolute value so that a model getting worse (e.g. a toy newly moved far away) also draws
attention. With n < 2 W attempts, both halves have n // 2 attempts; with fewer than 2, the
progress is 0. A model is chosen with probability `active_random_share` uniformly, otherwise in
proportion to progress (uniformly while every progress is 0).

The study's public implementation instead compared each competence with that of the nearest
earlier goal and smoothed the difference over about 1000 attempts; the windowed difference here
needs no neighbour search and reads directly as "recent minus older competence".
"""

from __future__ import annotations

import numpy as np

from learner.compiled import compiled
from learner.config import LearnerConfig
from learner.pairwise_sum import BLOCK, pairwise_sum


def competence(goal: np.ndarray, reached: np.ndarray) -> float:
    """-|goal - reached|, both (10,)."""
    diff = goal - reached
    return -float(np.sqrt(diff @ diff))


def weighted_choice(rng: np.random.Generator, p: np.ndarray) -> int:
    """`rng.choice(len(p), p=p)`: the same index from the same single draw, without its checks
    of p (a third of a choice's cost, every iteration). p (n,) non-negative, summing to 1.

    Generator.choice's own arithmetic: the normalised cumulative sum, searched for one uniform
    draw. tests/learner/test_same_draws.py holds it to Generator.choice draw by draw.
    """
    cdf = p.cumsum()
    cdf /= cdf[-1]
    return int(cdf.searchsorted(rng.random(), side="right"))


@compiled
def window_progress(ring: np.ndarray, n: int, half: int) -> float:  # pragma: no cover - compiled
    """|mean of the newest `half` (<= 128) competences - mean of the `half` before them| of a
    model whose attempt k sits at ring[k % len(ring)], n attempts made; 0 where half is 0. The
    means are ndarray.mean's arithmetic (NumPy's sum, then the division), compiled: every
    iteration updates one model's progress (tests/learner/test_pairwise_sum.py)."""
    if half == 0:
        return 0.0
    recent = np.empty(2 * half)  # attempts n - 2 half .. n - 1, oldest first
    for i in range(2 * half):
        recent[i] = ring[(n - 2 * half + i) % ring.shape[0]]
    newer = pairwise_sum(recent, half, half) / half
    older = pairwise_sum(recent, 0, half) / half
    return abs(newer - older)


class InterestModel:
    """Competence history of each model, and the choice of the model to train."""

    def __init__(self, n_models: int, config: LearnerConfig) -> None:
        if n_models <= 0:
            raise ValueError(f"need at least one model, got {n_models}")
        self.n_models = n_models
        self.mode = config.babbling
        self.random_share = config.active_random_share
        self.window = config.progress_window
        # Ring buffers of the last 2 W competences; attempt k of a model sits at k % (2 W).
        self._competences = np.zeros((n_models, 2 * self.window))
        self._attempts = np.zeros(n_models, dtype=np.int64)
        # Only the model just attempted changes its progress: cached, so that choosing costs
        # no pass over the histories.
        self._progress = np.zeros(n_models)

    @property
    def attempts(self) -> np.ndarray:
        """Attempts recorded per model (n_models,)."""
        return self._attempts.copy()

    def choose(self, rng: np.random.Generator) -> int:
        """Index of the model to train now (0-based into the model table)."""
        if self.mode == "random":
            return int(rng.integers(self.n_models))
        progress = self._progress
        total = progress.sum()
        if rng.random() < self.random_share or total <= 0.0:
            return int(rng.integers(self.n_models))
        return weighted_choice(rng, progress / total)

    def update(self, model: int, goal: np.ndarray, reached: np.ndarray) -> float:
        """Record the attempt of `model` at `goal` that reached `reached`; return its competence."""
        value = competence(goal, reached)
        k = self._attempts[model]
        self._competences[model, k % (2 * self.window)] = value
        self._attempts[model] = k + 1
        # Kept under random babbling too, where no choice reads it: the trial's log records
        # every model's progress at every iteration (one model's update, not ten).
        self._progress[model] = self._model_progress(model)
        return value

    def progress(self) -> np.ndarray:
        """Progress of each model (n_models,), as defined in the module docstring: the
        interest the next choice is drawn from under active babbling."""
        return self._progress.copy()

    def _model_progress(self, model: int) -> float:
        n = int(self._attempts[model])
        half = min(self.window, n // 2)
        if half <= BLOCK:  # the compiled sums' reach (learner/pairwise_sum.py): the default W
            return window_progress(self._competences[model], n, half)
        recent = self._competences[model, np.arange(n - 2 * half, n) % (2 * self.window)]
        return abs(float(recent[half:].mean()) - float(recent[:half].mean()))

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"competences": self._competences.copy(), "attempts": self._attempts.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        competences = np.asarray(state["competences"], dtype=np.float64)
        attempts = np.asarray(state["attempts"], dtype=np.int64)
        if competences.shape != self._competences.shape or attempts.shape != (self.n_models,):
            raise ValueError(
                f"interest state of shapes {competences.shape}, {attempts.shape} does not fit "
                f"{self.n_models} models with a progress window of {self.window}"
            )
        self._competences = competences.copy()
        self._attempts = attempts.copy()
        self._progress = np.array([self._model_progress(k) for k in range(self.n_models)])
