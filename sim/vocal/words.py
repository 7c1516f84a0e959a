"""Vowel targets, the caregiver's 6 words, their perfect trajectories, and recognition.

Vowel targets are the exact-path formants (`sim.vocal.formants`) of the VTL speaker's own vowel
shapes /o u i e y/, so that every vowel, hence every word, is within the agent's reach. They are
computed once by `fit_voice_model` and stored in data/vowels.npz; the study's Hz values stay in
`VoiceConfig.study_vowel_hz` for comparison.

A word of 3 vowels is a 5-point formant trajectory: v1, mid(v1, v2), v2, mid(v2, v3), v3, in
log2 Hz, midpoints taken in log2. Its 10D sound features are the 5 log2 F1 values minus
f1_offset, then the 5 log2 F2 values minus f2_offset (docs/protocol.md §4, §6).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

DATA_FILE = Path(__file__).parent / "data" / "vowels.npz"


def compute_vowel_targets(config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """(5, 2) log2 Hz: exact-path (F1, F2) of the speaker's vowel shapes, in config.vowels order.

    Calls VocalTractLab (a few ms per vowel). Raises RuntimeError if a vowel hits the fallback.
    """
    from sim.vocal.articulators import speaker_shapes
    from sim.vocal.formants import tract_formants

    log2_hz, ok = tract_formants(speaker_shapes(config.vowels))
    if not np.all(ok):
        raise RuntimeError(f"no exact formants for vowels {np.array(config.vowels)[~ok]}")
    return log2_hz


def save_vowel_targets(targets: np.ndarray, config: VoiceConfig = DEFAULT_VOICE) -> None:
    DATA_FILE.parent.mkdir(parents=True, exist_ok=True)
    np.savez(DATA_FILE, vowels=np.array(config.vowels), log2_hz=targets)


@functools.cache
def vowel_targets(config: VoiceConfig = DEFAULT_VOICE) -> dict[str, np.ndarray]:
    """Stored vowel targets: vowel name -> (2,) log2 Hz (F1, F2)."""
    if not DATA_FILE.exists():
        raise FileNotFoundError(
            f"{DATA_FILE} is missing: run `python -m sim.vocal.fitting.fit_voice_model` to build it"
        )
    with np.load(DATA_FILE) as d:
        stored = dict(zip((str(v) for v in d["vowels"]), d["log2_hz"], strict=True))
    return {v: stored[v] for v in config.vowels}


def normalise(log2_points: np.ndarray, config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """(..., 5, 2) log2 Hz at the 5 points -> (..., 10) features: F1 block, then F2 block."""
    pts = np.asarray(log2_points, dtype=float)
    f1 = pts[..., 0] - config.f1_offset
    f2 = pts[..., 1] - config.f2_offset
    return np.concatenate([f1, f2], axis=-1)


def word_trajectory(
    word: str,
    targets: dict[str, np.ndarray] | None = None,
    config: VoiceConfig = DEFAULT_VOICE,
) -> np.ndarray:
    """(5, 2) log2 Hz: the perfect trajectory of a word (v1, mid, v2, mid, v3)."""
    if word not in config.words:
        raise ValueError(f"unknown word {word!r}; expected one of {config.words}")
    targets = vowel_targets(config) if targets is None else targets
    v1, v2, v3 = (np.asarray(targets[c], float) for c in word)
    return np.stack([v1, (v1 + v2) / 2, v2, (v2 + v3) / 2, v3])


def word_features(
    word: str,
    targets: dict[str, np.ndarray] | None = None,
    config: VoiceConfig = DEFAULT_VOICE,
) -> np.ndarray:
    """(10,) normalised sound features of the perfect word."""
    return normalise(word_trajectory(word, targets, config), config)


@functools.cache
def _all_word_features(config: VoiceConfig) -> np.ndarray:
    feats = np.stack([word_features(w, config=config) for w in config.words])
    feats.flags.writeable = False  # cached and shared: nobody may change it in place
    return feats


def all_word_features(config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """(6, 10) read-only: the perfect features of config.words, in that order."""
    return _all_word_features(config)


def word_distances(features: np.ndarray, config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """Euclidean distances (..., 6) from sound features (..., 10) to each word."""
    diff = np.asarray(features, float)[..., None, :] - all_word_features(config)
    return np.sqrt(np.sum(diff**2, axis=-1))


def recognise(features: np.ndarray, config: VoiceConfig = DEFAULT_VOICE) -> str | None:
    """The word the caregiver hears in a sound (10,): the nearest word if within
    config.recognition_distance, else None."""
    dist = word_distances(features, config)
    best = int(np.argmin(dist))
    return config.words[best] if dist[best] < config.recognition_distance else None
