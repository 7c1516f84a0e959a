"""Model Babbling: sensorimotor models, nearest-neighbour memory, interest, the agent.

The learner sees motor, context and sensory vectors only, laid out as `models.layout` says; it
imports neither MuJoCo nor `sim`. `Agent`, `Proposal` and `LearnerConfig` are loaded on first
use, so that `learner.config` (which the command line reads for its choices) can be imported
without the agent's numba kernels.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from learner.agent import Agent, Proposal
    from learner.config import LearnerConfig

__all__ = ["Agent", "LearnerConfig", "Proposal"]


def __getattr__(name: str) -> Any:
    if name in ("Agent", "Proposal"):
        from learner import agent

        return getattr(agent, name)
    if name == "LearnerConfig":
        from learner import config

        return config.LearnerConfig
    raise AttributeError(f"module 'learner' has no attribute {name!r}")
