"""The stored voice commands that say each word (data/productions.npz, found by
`sim.vocal.vtl.produce`): `say(word)` is instant, and the caregiver's words sound through them.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from sim.dmp import voice_trajectory
from sim.vocal.audio import DEFAULT_DURATION_S, DEFAULT_PAD_S
from sim.vocal.vtl.audio import synthesise

DATA_FILE = Path(__file__).parent / "data" / "productions.npz"


@functools.cache
def _stored() -> dict[str, tuple[np.ndarray, float]]:
    if not DATA_FILE.exists():
        raise FileNotFoundError(
            f"{DATA_FILE} is missing: run `python -m sim.vocal.vtl.fitting.fit_voice_model` "
            "to build it"
        )
    with np.load(DATA_FILE) as d:
        return {
            str(w): (p, float(dist))
            for w, p, dist in zip(d["words"], d["params"], d["distances"], strict=True)
        }


def say(word: str) -> np.ndarray:
    """(28,) stored voice parameters that produce the word (a copy)."""
    stored = _stored()
    if word not in stored:
        raise ValueError(f"unknown word {word!r}; expected one of {tuple(stored)}")
    return stored[word][0].copy()


def stored_distances() -> dict[str, float]:
    """Word -> feature distance of its stored production (fast map, at fit time)."""
    return {w: d for w, (_, d) in _stored().items()}


def synthesise_word(
    word: str, duration_s: float = DEFAULT_DURATION_S, pad_s: float = DEFAULT_PAD_S
) -> tuple[np.ndarray, int]:
    """The caregiver's word as audio: the stored voice parameters that produce it
    (`say`) through the vocal DMP and VTL. Returns (waveform, rate Hz)."""
    return synthesise(voice_trajectory(say(word)), duration_s=duration_s, pad_s=pad_s)
