"""The caregiver (docs/protocol.md §6): where she stands, the words she uses, what she says
after an arm movement, what she hears of the agent's voice, and how she brings a toy.

Every rule of hers is written here once, whichever backend computes a movement (sim/movement.py):
what she says (`speak`), what she hears (`hear`), where she brings a toy (`target`) and how fast
(`brought_path`, the positions of the whole way, which the backends follow).

The words themselves (vowel targets, recognition distances) are the voice's (sim/vocal/words.py);
which word names which toy is hers, drawn once per room. What she does with a toy she brings is
her backend's carrying part (sim/grasping/carrying.py): carried by her hand, a mocap body welded
to the toy, lifted above the table, in the physical backend; placed directly, as in the study,
in the kinematic one; each backend's `simulate` follows her path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.layout import N_STEPS, TOYS
from sim import events as ev
from sim.config import WorldConfig
from sim.grasping.carrying import Carrying
from sim.movement import Brought, Holds
from sim.physics import PlayroomPhysics
from sim.vocal.config import VoiceConfig
from sim.vocal.voice import Voice


@dataclass(frozen=True)
class WordAssignment:
    """One run's words: names[i] is the name of toy i+1; distractors are the other 3."""

    names: tuple[str, ...]
    distractors: tuple[str, ...]

    def toy_of(self, word: str) -> int | None:
        """0-based index of the toy a word names, or None for a distractor."""
        return self.names.index(word) if word in self.names else None


def brought_path(start: np.ndarray, target: np.ndarray, rate: float) -> np.ndarray:
    """(N_STEPS, 2) where a toy she brings is after each control step: `rate` of the remaining
    way from `start` (2,) to `target` (2,) at every step (docs/protocol.md §6)."""
    # The same operations on each coordinate, in Python floats (IEEE doubles, as NumPy's): a
    # 50-step loop of 2-vector NumPy operations cost 180 us.
    path = np.empty((N_STEPS, 2))
    x, y = (float(v) for v in start)
    tx, ty = (float(v) for v in target)
    for k in range(N_STEPS):
        x += rate * (tx - x)
        y += rate * (ty - y)
        path[k] = x, y
    return path


def assign_words(rng: np.random.Generator, config: VoiceConfig) -> WordAssignment:
    """Shuffle the 6 words with rng: the first n_names name the toys, the rest are distractors."""
    order = rng.permutation(len(config.words))
    words = tuple(config.words[i] for i in order)
    return WordAssignment(names=words[: config.n_names], distractors=words[config.n_names :])


class Caregiver:
    """The caregiver of one room. `rng` is the room's generator: she draws her words from it
    now, and her place and distractors from it later, in the room's order of draws."""

    def __init__(
        self,
        carrying: Carrying,
        config: WorldConfig,
        vocal_tract: Voice,
        rng: np.random.Generator,
    ) -> None:
        self.carrying = carrying  # how she carries a toy in this world (her backend's part)
        self.config = config
        self.vocal_tract = vocal_tract
        self.words: WordAssignment = assign_words(rng, vocal_tract.config)
        # The toy she brings during this movement (0-based) and where it is to be after each
        # control step, or None.
        self.brought: Brought | None = None

    # Where she stands ----------------------------------------------------------------------
    def place(self, physics: PlayroomPhysics, rng: np.random.Generator) -> None:
        """A new position, uniform in the square [-box, box]^2."""
        box = self.config.caregiver_box
        position = rng.uniform(-box, box, size=2)
        d = physics.data.ptr
        d.mocap_pos[physics.caregiver_mocap, :2] = position
        d.mocap_pos[physics.caregiver_hand_mocap, :2] = position  # her hand rests by her

    def target(self, physics: PlayroomPhysics) -> np.ndarray:
        """(2,) midpoint between the caregiver and the arm's base at (0, 0)."""
        return physics.caregiver_position() / 2.0

    # What she says and hears ---------------------------------------------------------------
    def speak(self, holds: Holds, rng: np.random.Generator) -> tuple[np.ndarray, ev.Event]:
        """After an arm movement, from what the hand and the stick hold at its end: the name of
        the toy in the hand, else a random distractor. Returns the word's sound features (10,)
        and the event."""
        if holds.hand in TOYS:
            word, obj = self.words.names[TOYS.index(holds.hand)], holds.hand
        else:
            word, obj = self.words.distractors[rng.integers(len(self.words.distractors))], None
        features = self.vocal_tract.word_features(word)
        return features, ev.Event(ev.CAREGIVER_SAID, N_STEPS, obj=obj, word=word)

    def hear(self, physics: PlayroomPhysics, voice_formants: np.ndarray) -> list[ev.Event]:
        """She listens to the agent's coming sound, (N_STEPS, 2) log2 Hz; if it is a toy's
        name she starts bringing that toy."""
        tract = self.vocal_tract
        word = tract.recognise(tract.features_from_formants(voice_formants))
        if word is None:
            return []
        toy = self.words.toy_of(word)
        if toy is not None:
            self.start_bringing(physics, toy)
        return [ev.Event(ev.WORD_RECOGNISED, 1, obj=None if toy is None else TOYS[toy], word=word)]

    # How she brings a toy ------------------------------------------------------------------
    def start_bringing(self, physics: PlayroomPhysics, toy: int) -> None:
        """Take toy `toy` (0-based) and bring it over the coming control steps."""
        start = self.carrying.takes(physics, toy)
        path = brought_path(start, self.target(physics), self.config.caregiver_bring_rate)
        self.brought = Brought(toy, path)

    @property
    def bringing(self) -> int | None:
        """The index of the toy she is bringing, or None."""
        return None if self.brought is None else self.brought.toy

    def stop(self, physics: PlayroomPhysics) -> None:
        """Put the toy down where it is."""
        if self.brought is None:
            return
        self.carrying.puts_down(physics)
        self.brought = None
