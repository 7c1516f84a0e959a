"""DIVA-style articulators: 7 principal components of the VocalTractLab speaker's tract shapes.

DIVA's articulators are principal components of vocal-tract shapes; here the shapes are tract
states (19 VTL parameters) of the JD3 speaker that ships with `vocaltractlab-cython`. The corpus
is the speaker's vowel shapes and random blends of them. Articulator values live in [-1, 1]:
value a_k moves the tract along component k by a_k * scale_k, where scale_k is 1.25 times the
largest projection of the 5 study vowels /o u i e y/ on that component, so that every vowel lies
inside the box with a margin (|a_k| <= 0.8). Tract states are clipped to VTL's parameter ranges.

Why these 8 corpus vowels: with blends of all 11 of the speaker's vowels, 7 components explain
about 98% of the shape variance, but the part they miss moves the formants of /e/ by up to
0.66 log2 (an octave on F1 is a different vowel). Blends of 8 shapes span exactly 7 dimensions,
so the 5 study vowels plus /a E 2/ (the triple that best covers the remaining 3 vowels) are
reproduced exactly by the articulators while the box still reaches open and front-rounded shapes.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import vocaltractlab_cython as vtl

from models.layout import N_ARTICULATORS
from sim.vocal.config import DEFAULT_VOICE

# The 5 study vowels first, then the 3 extra shapes that complete a 7-dimensional span.
CORPUS_VOWELS: tuple[str, ...] = ("o", "u", "i", "e", "y", "a", "E", "2")
# Every VTL vowel shape of the speaker, to report how much of the speaker's vowel space the
# articulators cover.
ALL_SPEAKER_VOWELS: tuple[str, ...] = ("a", "e", "i", "o", "u", "y", "E", "2", "9", "O", "@")
N_BLENDS = 5000  # random blends in the corpus
SCALE_MARGIN = 1.25  # box half-width / largest vowel projection, per component
DATA_FILE = Path(__file__).parent / "data" / "articulators.npz"


def tract_param_ranges() -> tuple[np.ndarray, np.ndarray]:
    """VTL's (min, max) of the 19 tract parameters, each (19,), in their units (mostly cm)."""
    info = vtl.get_param_info("tract")
    return (np.array([p["min"] for p in info]), np.array([p["max"] for p in info]))


def speaker_shapes(names: tuple[str, ...]) -> np.ndarray:
    """(len(names), 19): the speaker's tract states for the named VTL shapes."""
    return np.array([vtl.get_shape(name, "tract") for name in names], dtype=float)


@dataclass(frozen=True)
class ArticulatorModel:
    """Linear articulators: tract = clip(lo + (hi - lo) * (mean + (a * scales) @ components)).

    PCA runs on tract parameters normalised by VTL's ranges ((x - lo) / (hi - lo)), so that no
    parameter dominates because of its unit.
    """

    mean: np.ndarray  # (19,) normalised corpus mean
    components: np.ndarray  # (7, 19) orthonormal principal axes in normalised units
    scales: np.ndarray  # (7,) normalised units per articulator unit
    lo: np.ndarray  # (19,) VTL parameter minima
    hi: np.ndarray  # (19,) VTL parameter maxima
    explained_variance_ratio: np.ndarray  # (7,) of the corpus variance, per component
    speaker_vowel_coverage: float  # fraction of the variance of all 11 speaker vowels explained
    vowel_names: tuple[str, ...]  # the study vowels, in `DEFAULT_VOICE.vowels` order
    vowel_articulators: np.ndarray  # (5, 7) articulator values of the study vowels

    def to_tract(self, artic: np.ndarray) -> np.ndarray:
        """Articulator values (..., 7), in [-1, 1], -> VTL tract states (..., 19)."""
        artic = np.asarray(artic, dtype=float)
        z = self.mean + (artic * self.scales) @ self.components
        return np.clip(self.lo + (self.hi - self.lo) * z, self.lo, self.hi)

    def vowel(self, name: str) -> np.ndarray:
        """(7,) articulator values of one study vowel."""
        return self.vowel_articulators[self.vowel_names.index(name)].copy()

    def save(self, path: Path = DATA_FILE) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(
            path,
            mean=self.mean,
            components=self.components,
            scales=self.scales,
            lo=self.lo,
            hi=self.hi,
            explained_variance_ratio=self.explained_variance_ratio,
            speaker_vowel_coverage=self.speaker_vowel_coverage,
            vowel_names=np.array(self.vowel_names),
            vowel_articulators=self.vowel_articulators,
        )

    @classmethod
    def load(cls, path: Path = DATA_FILE) -> ArticulatorModel:
        with np.load(path) as d:
            return cls(
                mean=d["mean"],
                components=d["components"],
                scales=d["scales"],
                lo=d["lo"],
                hi=d["hi"],
                explained_variance_ratio=d["explained_variance_ratio"],
                speaker_vowel_coverage=float(d["speaker_vowel_coverage"]),
                vowel_names=tuple(str(v) for v in d["vowel_names"]),
                vowel_articulators=d["vowel_articulators"],
            )


def build_articulator_model(seed: int = 0, n_blends: int = N_BLENDS) -> ArticulatorModel:
    """PCA of the speaker's corpus (CORPUS_VOWELS and Dirichlet(1) blends of them)."""
    lo, hi = tract_param_ranges()
    shapes = speaker_shapes(CORPUS_VOWELS)
    rng = np.random.default_rng(seed)
    weights = rng.dirichlet(np.ones(len(CORPUS_VOWELS)), size=n_blends)
    corpus = (np.vstack([shapes, weights @ shapes]) - lo) / (hi - lo)
    mean = corpus.mean(axis=0)
    _, sing, vt = np.linalg.svd(corpus - mean, full_matrices=False)
    components = vt[:N_ARTICULATORS]
    # Fix each axis' sign (SVD's is arbitrary) so that a rebuild gives the same articulators.
    largest = components[np.arange(N_ARTICULATORS), np.argmax(np.abs(components), axis=1)]
    components = components * np.sign(largest)[:, None]
    explained = sing[:N_ARTICULATORS] ** 2 / np.sum(sing**2)

    study = DEFAULT_VOICE.vowels
    proj = (shapes[: len(study)] - lo) / (hi - lo) - mean
    proj = proj @ components.T  # (5, 7) in normalised units
    scales = SCALE_MARGIN * np.abs(proj).max(axis=0)

    all_vowels = (speaker_shapes(ALL_SPEAKER_VOWELS) - lo) / (hi - lo)
    centred = all_vowels - all_vowels.mean(axis=0)
    resid = (all_vowels - mean) - ((all_vowels - mean) @ components.T) @ components
    resid = resid - resid.mean(axis=0)
    coverage = 1.0 - float(np.sum(resid**2) / np.sum(centred**2))

    return ArticulatorModel(
        mean=mean,
        components=components,
        scales=scales,
        lo=lo,
        hi=hi,
        explained_variance_ratio=explained,
        speaker_vowel_coverage=coverage,
        vowel_names=study,
        vowel_articulators=proj / scales,
    )


@functools.cache
def default_articulators() -> ArticulatorModel:
    """The stored articulator model (data/articulators.npz, built by fit_voice_model)."""
    if not DATA_FILE.exists():
        raise FileNotFoundError(
            f"{DATA_FILE} is missing: run `python -m sim.vocal.vtl.fitting.fit_voice_model` "
            "to build it"
        )
    return ArticulatorModel.load(DATA_FILE)
