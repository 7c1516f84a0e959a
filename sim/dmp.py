"""Discrete Dynamical Movement Primitives, vectorised over dimensions (docs/protocol.md §2).

A DMP turns a start, an end and a few basis-function weights per dimension into a smooth
n-step trajectory. The forcing term is not multiplied by (end - start), so a movement that
starts and ends at the same place can still have a shape (the study's arm starts at rest, 0).
Two kinds (`WorldConfig.dmp`):
- "study": the study's own DMP (its `dmp/` package): phase x_t = 0.98^t, centres exp(-d) for d
  evenly from 0.9 to 0, widths 8 n^2 / c^1.5, forcing x sum(psi w) / sum(psi), and a velocity
  that is never integrated, so each step is y <- y + 0.0625 (g - y) + 0.0004 f;
- "project": a pydmps-style spring-damper (Ijspeert et al. 2013) with integrated velocity.
Both are linear in (start, end, weights), so each is integrated once per unit input and every
rollout is one matrix product.
"""

from __future__ import annotations

import functools

import numpy as np

from models.layout import (
    ARM_BASIS_FUNCTIONS,
    N_ARTICULATORS,
    N_JOINTS,
    N_STEPS,
    VOICE_BASIS_FUNCTIONS,
)
from sim.config import DEFAULT_WORLD, DMP_KINDS, WorldConfig

# Spring-damper gains of the transformation system, critically damped (beta = alpha / 4).
ALPHA_Y = 25.0
BETA_Y = ALPHA_Y / 4.0
# The canonical phase decays from 1 to exp(-1) over the movement (pydmps's default, used by
# the study through explauto), so the forcing term shapes the whole movement.
ALPHA_X = 1.0
# Euler integration substeps per output step, for accuracy with stiff forcing.
INTEGRATION_SUBSTEPS = 10


def _basis(n_bfs: int, phase: np.ndarray) -> np.ndarray:
    """Normalised Gaussian activations (len(phase), n_bfs), centres spaced evenly in time."""
    centres = np.exp(-ALPHA_X * np.linspace(0.0, 1.0, n_bfs))
    widths = n_bfs**1.5 / centres / ALPHA_X
    psi = np.exp(-widths * (phase[:, None] - centres) ** 2)
    return psi / psi.sum(axis=1, keepdims=True)


def _integrate(start: np.ndarray, end: np.ndarray, weights: np.ndarray, n_steps: int) -> np.ndarray:
    """Euler-integrate DMPs of `d` dimensions: (d,), (d,), (d, n_bfs) -> (d, n_steps)."""
    n_fine = n_steps * INTEGRATION_SUBSTEPS
    dt = 1.0 / n_fine
    phase = np.exp(-ALPHA_X * np.arange(n_fine) * dt)
    forcing = phase[:, None] * (_basis(weights.shape[1], phase) @ weights.T)  # (n_fine, d)
    y = start.astype(float).copy()
    yd = np.zeros_like(y)
    out = np.empty((n_fine, y.size))
    for k in range(n_fine):
        ydd = ALPHA_Y * (BETA_Y * (end - y) - yd) + forcing[k]
        yd = yd + ydd * dt
        y = y + yd * dt
        out[k] = y
    return out[INTEGRATION_SUBSTEPS - 1 :: INTEGRATION_SUBSTEPS].T


# The study's DMP (its dmp/cs.py, dmp_discrete.py): dt = 1/50, gains alpha_y = 25,
# beta_y = alpha_y / 4, the phase decaying by (1 - dt) per step.
STUDY_DT = 1.0 / 50.0
STUDY_CENTRE_SPAN = 0.9  # centres exp(-d) for d evenly from 0.9 to 0
STUDY_WIDTH_GAIN = 8.0  # widths 8 n^2 / c^1.5


def _integrate_study(
    start: np.ndarray, end: np.ndarray, weights: np.ndarray, n_steps: int
) -> np.ndarray:
    """The study's first-order DMP: (d,), (d,), (d, n_bfs) -> (d, n_steps), y after each step."""
    n_bfs = weights.shape[1]
    phase = (1.0 - STUDY_DT) ** np.arange(n_steps)
    centres = np.exp(-np.linspace(STUDY_CENTRE_SPAN, 0.0, n_bfs))
    widths = STUDY_WIDTH_GAIN * n_bfs**2 / centres**1.5
    psi = np.exp(-widths * (phase[:, None] - centres) ** 2)
    forcing = phase[:, None] * (psi @ weights.T) / psi.sum(axis=1, keepdims=True)  # (n, d)
    gain = ALPHA_Y * BETA_Y * STUDY_DT**2  # 0.0625
    y = start.astype(float).copy()
    out = np.empty((n_steps, y.size))
    for k in range(n_steps):
        y = y + gain * (end - y) + STUDY_DT**2 * forcing[k]
        out[k] = y
    return out.T


@functools.lru_cache(maxsize=8)
def response_matrix(n_bfs: int, n_steps: int, kind: str = "project") -> np.ndarray:
    """(2 + n_bfs, n_steps): the trajectory of a unit start, a unit end and each unit weight.

    The DMP is linear in (start, end, weights) from rest velocity, so integrating each unit
    input once turns every later rollout into one matrix product.
    """
    if kind not in DMP_KINDS:
        raise ValueError(f"unknown DMP {kind!r}: one of {DMP_KINDS}")
    eye = np.eye(2 + n_bfs)
    integrate = _integrate_study if kind == "study" else _integrate
    return integrate(eye[:, 0], eye[:, 1], eye[:, 2:], n_steps)


def rollout(
    start: np.ndarray,
    end: np.ndarray,
    weights: np.ndarray,
    n_steps: int = N_STEPS,
    kind: str = "project",
) -> np.ndarray:
    """Trajectories of `d` DMPs.

    start, end: (d,); weights: (d, n_bfs), already scaled. Returns (d, n_steps): the positions
    after each of the n_steps equal time steps of a movement lasting 1 (unitless time).
    """
    weights = np.asarray(weights, dtype=float)
    if weights.ndim != 2:  # a single DMP's weights (n_bfs,)
        weights = np.atleast_2d(weights)
    inputs = np.empty((weights.shape[0], 2 + weights.shape[1]))  # C order, as column_stack's
    inputs[:, 0] = start
    inputs[:, 1] = end
    inputs[:, 2:] = weights
    return inputs @ response_matrix(weights.shape[1], n_steps, kind)


def arm_trajectory(m: np.ndarray, config: WorldConfig = DEFAULT_WORLD) -> np.ndarray:
    """21 arm parameters in [-1, 1] -> (3, n_steps) joint angles in rad, relative to rest.

    Per joint: `ARM_BASIS_FUNCTIONS` weights then 1 end position. The DMP starts at rest (0); the
    trajectory is bounded to [-1, 1] and scaled by pi (docs/protocol.md §2).
    """
    per_joint = np.asarray(m, dtype=float).reshape(N_JOINTS, ARM_BASIS_FUNCTIONS + 1)
    weights = per_joint[:, :-1] * config.dmp_weight_scale
    traj = rollout(np.zeros(N_JOINTS), per_joint[:, -1], weights, N_STEPS, config.dmp)
    # np.clip's values (min(max(x, lo), hi)) without its Python wrapper: an arm command's
    # and a voice command's trajectory are bounded every iteration.
    return np.pi * np.minimum(np.maximum(traj, -1.0), 1.0)


def voice_trajectory(m: np.ndarray, config: WorldConfig = DEFAULT_WORLD) -> np.ndarray:
    """28 voice parameters in [-1, 1] -> (7, n_steps) articulator values in [-1, 1].

    Per articulator: start, end, then `VOICE_BASIS_FUNCTIONS` weights (docs/protocol.md §2).
    """
    per_art = np.asarray(m, dtype=float).reshape(N_ARTICULATORS, VOICE_BASIS_FUNCTIONS + 2)
    weights = per_art[:, 2:] * config.dmp_weight_scale
    traj = rollout(per_art[:, 0], per_art[:, 1], weights, N_STEPS, config.dmp)
    return np.minimum(np.maximum(traj, -1.0), 1.0)  # np.clip's values, as above
