"""`Voice`: what the world uses of a vocal tract, whichever tract it is (sim/vocal/registry.py).

The world sends articulator frames (7 values in [-1, 1] each) and gets their formants (log2 Hz);
a 28-parameter vocal command goes through the vocal DMP (`sim.dmp.voice_trajectory`) to a (7, 50)
articulator trajectory, whose formants at the 5 sample steps are the 10D sound features
(docs/protocol.md §4), which the caregiver recognises as a word or not. A tract implements the
formants of frames, its vowel targets (where in formant space its words lie) and the audio of a
trajectory and of a word; the rest is common and lives here.
"""

from __future__ import annotations

import abc

import numpy as np

from models.layout import N_ARTICULATORS, SAMPLE_INDICES, VOICE_DIM
from sim.config import WorldConfig
from sim.dmp import voice_trajectory
from sim.vocal.config import VoiceConfig
from sim.vocal.words import normalise, word_trajectory


def check_box(x: np.ndarray, what: str) -> None:
    """ValueError unless every value of x is finite and in [-1, 1]."""
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{what} contains NaN or infinite values")
    if np.any(np.abs(x) > 1.0):
        raise ValueError(
            f"{what} must lie in [-1, 1]; got values in [{x.min():.3g}, {x.max():.3g}]"
        )


class Voice(abc.ABC):
    """A vocal tract as the world uses it.

    `name`: as the registry names it. exact: the tract's exact (slow) path instead of its fast
    one, where it has two; frames whose exact formants fail are counted in `n_fallbacks`.
    config: the voice's numbers; world: the world whose vocal DMP turns commands into
    articulator trajectories.
    """

    name: str
    # What a video says of the sound it plays (experiments/video).
    sound_label: str
    # What building the tract raises when the user's data it computes from is missing or
    # unusable (DIVA's); none for a tract whose data ships with the project.
    user_data_errors: tuple[type[Exception], ...] = ()

    def __init__(self, exact: bool, config: VoiceConfig, world: WorldConfig) -> None:
        self.exact = exact
        self.config = config
        self.world = world
        self.n_fallbacks = 0
        self._sample_idx = np.array(SAMPLE_INDICES)
        targets = self.vowel_targets()
        self._targets = targets
        words = np.stack(
            [normalise(word_trajectory(w, targets, config), config) for w in config.words]
        )
        words.flags.writeable = False  # shared by every caller: nobody may change it in place
        self._word_features = words

    @abc.abstractmethod
    def frame_formants(self, artic: np.ndarray) -> np.ndarray:
        """Checked articulator frames (..., 7) in [-1, 1] -> (..., 2) log2 Hz (F1, F2)."""

    def frame_formants_at(self, artic: np.ndarray, rows: np.ndarray) -> np.ndarray | None:
        """`frame_formants(artic)[rows]` where the tract computes some frames for less than
        all (the same numbers); None where it computes every frame anyway."""
        return None

    @abc.abstractmethod
    def vowel_targets(self) -> dict[str, np.ndarray]:
        """Vowel name -> (2,) log2 Hz (F1, F2): where this tract's words lie."""

    @abc.abstractmethod
    def audio(self, artic_traj: np.ndarray) -> tuple[np.ndarray, int]:
        """(7, n_steps) articulator trajectory -> (waveform, sample rate in Hz)."""

    @abc.abstractmethod
    def word_audio(self, word: str) -> tuple[np.ndarray, int]:
        """The caregiver's word as audio: (waveform, sample rate in Hz)."""

    def formants(self, artic: np.ndarray) -> np.ndarray:
        """Articulator values (..., 7) in [-1, 1] -> (..., 2) log2 Hz (F1, F2)."""
        artic = np.asarray(artic, dtype=float)
        if artic.ndim == 0 or artic.shape[-1] != N_ARTICULATORS:
            raise ValueError(
                f"articulators must have shape (..., {N_ARTICULATORS}); got {artic.shape}"
            )
        check_box(artic, "articulators")
        return self.frame_formants(artic)

    def trajectory(self, m: np.ndarray) -> np.ndarray:
        """28 voice parameters in [-1, 1] -> (7, n_steps) articulator trajectory."""
        m = np.asarray(m, dtype=float)
        if m.shape != (VOICE_DIM,):
            raise ValueError(f"voice command must have shape ({VOICE_DIM},); got {m.shape}")
        check_box(m, "voice command")
        return voice_trajectory(m, self.world)

    def trajectory_formants(self, artic_traj: np.ndarray) -> np.ndarray:
        """(7, n_steps) articulator trajectory -> (n_steps, 2) log2 Hz, one row per control
        step (what the sound sensor reads at each step)."""
        artic_traj = np.asarray(artic_traj, dtype=float)
        if artic_traj.ndim != 2 or artic_traj.shape[0] != N_ARTICULATORS:
            raise ValueError(
                f"articulator trajectory must have shape ({N_ARTICULATORS}, "
                f"n_steps); got {artic_traj.shape}"
            )
        return self.formants(artic_traj.T)

    def features_from_formants(self, step_formants: np.ndarray) -> np.ndarray:
        """(n_steps, 2) log2 Hz per step -> (10,) normalised features at the 5 sample steps."""
        return normalise(np.asarray(step_formants)[self._sample_idx], self.config)

    def sound_features(self, m: np.ndarray) -> np.ndarray:
        """28 voice parameters -> (10,) normalised sound features (docs/protocol.md §4).

        Only the 5 sample steps go through the formants.
        """
        traj = self.trajectory(m)
        return normalise(self.formants(traj[:, self._sample_idx].T), self.config)

    def data_record(self) -> dict[str, str]:
        """What of the user's data this tract computes from, for a trial's provenance: {} for
        a tract whose data ships with the project."""
        return {}

    # The words in this tract's formant space (sim/vocal/words.py) ----------------------------
    def word_trajectory(self, word: str) -> np.ndarray:
        """(5, 2) log2 Hz: the perfect trajectory of a word (v1, mid, v2, mid, v3)."""
        return word_trajectory(word, self._targets, self.config)

    def word_features(self, word: str) -> np.ndarray:
        """(10,) normalised sound features of the perfect word."""
        if word not in self.config.words:
            raise ValueError(f"unknown word {word!r}; expected one of {self.config.words}")
        return self._word_features[self.config.words.index(word)].copy()

    def all_word_features(self) -> np.ndarray:
        """(6, 10) read-only: the perfect features of config.words, in that order."""
        return self._word_features

    def word_distances(self, features: np.ndarray) -> np.ndarray:
        """Euclidean distances (..., 6) from sound features (..., 10) to each word."""
        diff = np.asarray(features, float)[..., None, :] - self._word_features
        return np.sqrt(np.add.reduce(diff**2, axis=-1))  # np.sum's arithmetic, less overhead

    def recognise(self, features: np.ndarray) -> str | None:
        """The word the caregiver hears in a (10,) sound: the nearest word if within
        config.recognition_distance, else None."""
        dist = self.word_distances(features)
        best = int(dist.argmin())
        return self.config.words[best] if dist[best] < self.config.recognition_distance else None
