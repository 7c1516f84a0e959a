"""What the environments of sim/envs/ share: the room each episode plays in, the layout and
bounds of what they observe, and the study's episode length.

An episode is one `Playroom`, built fresh from a seed (a few tens of milliseconds), so that an
episode of seed s is the world of `Playroom(seed=s)`, the room of a trial of that seed: its
toys placed and its caregiver moved between iterations by the room itself
(`Playroom.act`, sim/experimenter.py), exactly as in a trial.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from models.layout import CONTEXT_DIM, SENSORY_DIM, block_slice
from models.presets import DEFAULT_PRESET
from models.tracts import TRACTS
from models.world import Feedback
from sim import events as ev
from sim.config import WorldConfig, world_preset
from sim.envs.versions import STUDY_ITERATIONS
from sim.grasping.names import DEFAULT_GRASP
from sim.playroom import Playroom
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

# The sound block's bound (normalised log2 Hz, docs/protocol.md §4): four octaves either side of
# the reference formants (F1 from 22 Hz to 5.8 kHz, F2 from 76 Hz to 19 kHz), beyond any voice;
# random commands stay within +-1.6 in both tracts.
SOUND_BOUND = 4.0
# The events a step counts, in this order (sim/events.py).
EVENT_KINDS: tuple[str, ...] = ev.KINDS
# How a new episode's seed is drawn when reset() is given none: an integer below this.
SEED_BOUND = 2**31


@dataclass(frozen=True)
class RoomSettings:
    """The world every episode of an environment is built with; `iterations` per episode (None:
    no end of its own)."""

    grasp: str
    config: WorldConfig
    voice_config: VoiceConfig
    iterations: int | None

    def room(self, seed: int) -> Playroom:
        return Playroom(self.grasp, seed=seed, config=self.config, voice=self.voice_config)


def room_settings(
    grasp: str = DEFAULT_GRASP,
    preset: str | None = None,
    config: WorldConfig | None = None,
    voice: str | None = None,
    voice_config: VoiceConfig = DEFAULT_VOICE,
    iterations: int | None = STUDY_ITERATIONS,
) -> RoomSettings:
    """The settings checked (one-line ValueError): `config` is the world's numbers, or else
    those of `preset` (the default preset's when neither is given), not both; `voice` names the
    vocal tract as `playroom --voice` does (None: the config's), `voice_config` its numbers."""
    if preset is not None and config is not None:
        raise ValueError("give a preset or a config, not both (a config is a whole world)")
    voice = checked_voice(voice)
    voice_config = _checked_voice_config(voice_config)
    if config is None:
        config = world_preset(DEFAULT_PRESET if preset is None else preset)
    if voice is not None:
        # The tract is a field of the world's config (sim/config.py): the name replaces it.
        config = dataclasses.replace(config, voice=voice)
    if iterations is not None:
        if isinstance(iterations, bool) or not isinstance(iterations, int | np.integer):
            raise ValueError(f"iterations must be a positive integer, got {iterations!r}")
        if iterations < 1:
            raise ValueError(f"iterations must be a positive integer, got {iterations}")
        iterations = int(iterations)
    settings = RoomSettings(grasp, config, voice_config, iterations)
    settings.room(0)  # ValueError naming the backends, or a config the MJCF disagrees with
    return settings


def checked_voice(voice: object) -> str | None:
    """A vocal tract's name as the command line's `--voice` takes it, or None; ValueError in one
    line (a VoiceConfig given for it included: that is `voice_config`)."""
    if voice is not None and not isinstance(voice, str):
        kind = type(voice).__name__
        raise ValueError(
            f"voice is the vocal tract's name, one of {', '.join(TRACTS)}, got a {kind} (the "
            "voice's numbers, a VoiceConfig, are voice_config)"
        )
    if voice is not None and voice not in TRACTS:
        raise ValueError(f"unknown voice {voice!r}: one of {', '.join(TRACTS)}")
    return voice


def _checked_voice_config(value: object) -> VoiceConfig:
    if not isinstance(value, VoiceConfig):
        raise ValueError(f"voice_config must be a VoiceConfig, got a {type(value).__name__}")
    return value


def checked_seed(seed: object) -> int:
    """A room's seed: a non-negative integer, or ValueError."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


@dataclass(frozen=True)
class ObservationBounds:
    """How far each observed number can go: positions within the table (its half-size in the
    MJCF, m), sounds within SOUND_BOUND."""

    context: np.ndarray  # (10,)
    feedback: np.ndarray  # (60,)

    @classmethod
    def of(cls, room: Playroom) -> ObservationBounds:
        table = float(room.physics.named.model.geom_size["table", 0])
        feedback = np.full(SENSORY_DIM, table)
        feedback[block_slice("sound")] = SOUND_BOUND
        return cls(np.full(CONTEXT_DIM, table), feedback)


def observed(room: Playroom, feedback: Feedback | None, bounds: ObservationBounds) -> dict:
    """The context of the next movement (10,), the last movement's feedback (60,; zeros before
    the first) and its event counts (one per EVENT_KINDS), as new arrays. RuntimeError if the
    world left the bounds its spaces declare (a fault of the world, never hidden by clipping)."""
    context = np.array(room.context(), dtype=np.float64)
    s = np.zeros(SENSORY_DIM) if feedback is None else np.array(feedback.s, dtype=np.float64)
    for name, value, high in (
        ("context", context, bounds.context),
        ("feedback", s, bounds.feedback),
    ):
        outside = np.flatnonzero(~(np.abs(value) <= high))
        if outside.size:
            raise RuntimeError(
                f"the {name} left its declared bounds at indices {outside.tolist()} "
                f"(values {value[outside].tolist()})"
            )
    counts = np.zeros(len(EVENT_KINDS), dtype=np.int64)
    for event in [] if feedback is None else feedback.events:
        counts[EVENT_KINDS.index(event.kind)] += 1
    return {"context": context, "feedback": s, "events": counts}


def event_dicts(feedback: Feedback) -> list[dict]:
    """The movement's events as plain dicts (kind, step, obj, by, word), in step order."""
    return [
        {"kind": e.kind, "step": e.step, "obj": e.obj, "by": e.by, "word": e.word}
        for e in feedback.events
    ]
