"""Voice commands that say each word: found by optimisation, stored so `say(word)` is instant.

For each word, the 28 vocal DMP parameters are optimised so that the sound features (through
the fast formant map) come as close as possible to the word's perfect features:

1. A first guess from linear algebra: the DMP is linear in (start, end, weights), so per
   articulator a bounded least-squares fit makes the trajectory pass, at the 5 sample steps,
   through the articulator values of v1, mid(v1, v2), v2, mid(v2, v3), v3.
2. L-BFGS-B (bounds [-1, 1]) on the squared feature distance, from that guess and from
   perturbed copies of it; the best result wins.

`fit_voice_model` stores the results in data/productions.npz (read by
`sim.vocal.vtl.productions`); `compute_productions` redoes it.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear, minimize

from models.layout import N_STEPS, SAMPLE_INDICES, VOICE_BASIS_FUNCTIONS, VOICE_DIM
from sim.config import DEFAULT_WORLD, WorldConfig
from sim.dmp import rollout
from sim.vocal.vtl.productions import DATA_FILE
from sim.vocal.vtl.tract import VocalTract

N_STARTS = 8  # optimisation starts per word: the linear guess and 7 perturbations of it
START_NOISE = 0.2  # std of the perturbations, in parameter units


def dmp_response(world: WorldConfig = DEFAULT_WORLD) -> np.ndarray:
    """(2 + VOICE_BASIS_FUNCTIONS, N_STEPS): the articulator trajectory of each unit parameter
    (start, end, each weight in [-1, 1] units), before clipping. The DMP is linear in them."""
    n_in = 2 + VOICE_BASIS_FUNCTIONS
    eye = np.eye(n_in)
    return rollout(eye[:, 0], eye[:, 1], eye[:, 2:] * world.dmp_weight_scale, N_STEPS, world.dmp)


def initial_guess(word: str, tract: VocalTract) -> np.ndarray:
    """(28,) parameters whose articulator trajectory passes near the word's vowels and
    midpoints (in articulator space) at the 5 sample steps."""
    art = tract.articulators
    v1, v2, v3 = (art.vowel(c) for c in word)
    points = np.stack([v1, (v1 + v2) / 2, v2, (v2 + v3) / 2, v3])  # (5, 7)
    resp = dmp_response(tract.world)[:, list(SAMPLE_INDICES)].T  # (5, 4)
    per_art = [lsq_linear(resp, points[:, k], bounds=(-1.0, 1.0)).x for k in range(7)]
    return np.concatenate(per_art)  # per articulator: start, end, weights (sim.dmp layout)


def find_word_params(
    word: str, tract: VocalTract, n_starts: int = N_STARTS, seed: int = 0
) -> tuple[np.ndarray, float]:
    """Best (28,) voice parameters for a word and their feature distance to it (10D)."""
    target = tract.word_features(word)
    rng = np.random.default_rng(seed)

    def loss(m: np.ndarray) -> float:
        diff = tract.sound_features(np.clip(m, -1.0, 1.0)) - target
        return float(diff @ diff)

    guess = initial_guess(word, tract)
    starts = [guess] + [
        np.clip(guess + START_NOISE * rng.standard_normal(VOICE_DIM), -1.0, 1.0)
        for _ in range(n_starts - 1)
    ]
    best_m, best_loss = guess, loss(guess)
    for x0 in starts:
        res = minimize(loss, x0, method="L-BFGS-B", bounds=[(-1.0, 1.0)] * VOICE_DIM)
        if res.fun < best_loss:
            best_m, best_loss = np.clip(res.x, -1.0, 1.0), float(res.fun)
    return best_m, float(np.sqrt(best_loss))


def compute_productions(
    tract: VocalTract | None = None, n_starts: int = N_STARTS, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """Params (6, 28) and distances (6,) for config.words, in order (fast map by default)."""
    tract = VocalTract() if tract is None else tract
    found = [
        find_word_params(w, tract, n_starts, seed + i) for i, w in enumerate(tract.config.words)
    ]
    return np.stack([m for m, _ in found]), np.array([d for _, d in found])


def save_productions(words: tuple[str, ...], params: np.ndarray, distances: np.ndarray) -> None:
    DATA_FILE.parent.mkdir(parents=True, exist_ok=True)
    np.savez(DATA_FILE, words=np.array(words), params=params, distances=distances)
