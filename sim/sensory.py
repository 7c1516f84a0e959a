"""The feedback s (60,) the learner perceives, sampled from a movement's positions and sound."""

from __future__ import annotations

import numpy as np

from models.layout import N_STEPS, SAMPLE_INDICES, SENSORY_DIM, TRACKED_OBJECTS, block_slice

SAMPLE_STEPS = np.array(SAMPLE_INDICES)  # the control steps (0-based) s samples


def _flat_sample_indices() -> tuple[np.ndarray, np.ndarray]:
    """Flat indices into (N_STEPS, 5, 2) positions and (N_STEPS, 2) sound of s's values: per
    object its 5 x then its 5 y samples, then the sound's 5 F1 then 5 F2 samples."""
    steps = np.arange(N_STEPS * len(TRACKED_OBJECTS) * 2).reshape(N_STEPS, -1, 2)
    objects = steps[SAMPLE_STEPS].transpose(1, 2, 0).ravel()
    sound = np.arange(N_STEPS * 2).reshape(N_STEPS, 2)[SAMPLE_STEPS].T.ravel()
    return objects, sound


_OBJECT_SAMPLES, _SOUND_SAMPLES = _flat_sample_indices()


def sensory_from(positions: np.ndarray, sound: np.ndarray) -> np.ndarray:
    """(60,) from (N_STEPS, 5, 2) positions and (N_STEPS, 2) sound, sampled at SAMPLE_STEPS (one
    `take` each: this runs every iteration)."""
    s = np.empty(SENSORY_DIM)
    s[: _OBJECT_SAMPLES.size] = positions.take(_OBJECT_SAMPLES)
    s[block_slice("sound")] = sound.take(_SOUND_SAMPLES)
    return s
