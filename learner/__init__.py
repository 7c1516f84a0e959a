"""Model Babbling: sensorimotor models, nearest-neighbour memory, interest, the agent.

The learner sees motor, context and sensory vectors only, laid out as `models.layout` says; it
imports neither MuJoCo nor `sim`.
"""

from learner.agent import Agent, Proposal
from learner.config import LearnerConfig
from models.layout import MODELS, ModelSpec

__all__ = ["MODELS", "Agent", "LearnerConfig", "ModelSpec", "Proposal"]
