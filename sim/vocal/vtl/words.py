"""VocalTractLab's vowel targets (the speaker's own) and its words: features and recognition.

Vowel targets are the exact-path formants (`sim.vocal.vtl.formants`) of the VTL speaker's own
vowel shapes /o u i e y/, so that every vowel, hence every word, is within the agent's reach.
They are computed once by `fit_voice_model` and stored in data/vowels.npz; the study's Hz values
stay in `VoiceConfig.study_vowel_hz` for comparison (DIVA's tract uses those).

The words' trajectories and features follow from the targets as for any tract
(`sim.vocal.words`); the functions here take VocalTractLab's targets unless given others, for
the build-time fit and the checks that need no tract object (`VocalTract` has the same numbers).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.words import normalise, word_trajectory

DATA_FILE = Path(__file__).parent / "data" / "vowels.npz"


def compute_vowel_targets(config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """(5, 2) log2 Hz: exact-path (F1, F2) of the speaker's vowel shapes, in config.vowels order.

    Calls VocalTractLab (a few ms per vowel). Raises RuntimeError if a vowel hits the fallback.
    """
    from sim.vocal.vtl.articulators import speaker_shapes
    from sim.vocal.vtl.formants import tract_formants

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
            f"{DATA_FILE} is missing: run `python -m sim.vocal.vtl.fitting.fit_voice_model` "
            "to build it"
        )
    with np.load(DATA_FILE) as d:
        stored = dict(zip((str(v) for v in d["vowels"]), d["log2_hz"], strict=True))
    return {v: stored[v] for v in config.vowels}


def word_features(
    word: str,
    targets: dict[str, np.ndarray] | None = None,
    config: VoiceConfig = DEFAULT_VOICE,
) -> np.ndarray:
    """(10,) normalised sound features of the perfect word (VocalTractLab's targets if None)."""
    targets = vowel_targets(config) if targets is None else targets
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
