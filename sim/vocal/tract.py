"""`VocalTract`: what the world uses of the voice, with input checks and fallback counting.

Articulator values (7 per frame) in [-1, 1] go to formants (log2 Hz) either through the fast
fitted map (default; microseconds per movement) or the exact path (VocalTractLab area function
and lossless-tube resonances; about 5 ms per frame). A 28-parameter vocal command goes through
the vocal DMP (`sim.dmp.voice_trajectory`) to a (7, 50) articulator trajectory, whose formants
at the 5 sample steps are the 10D sound features (docs/protocol.md §4).
"""

from __future__ import annotations

import numpy as np

from models.layout import N_ARTICULATORS, SAMPLE_INDICES, VOICE_DIM
from sim.config import DEFAULT_WORLD, WorldConfig
from sim.dmp import voice_trajectory
from sim.vocal.articulators import ArticulatorModel, default_articulators
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.formant_map import FormantMap, default_formant_map
from sim.vocal.formants import tract_formants
from sim.vocal.words import normalise, recognise


def _check_box(x: np.ndarray, what: str) -> None:
    """ValueError unless every value of x is finite and in [-1, 1]."""
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{what} contains NaN or infinite values")
    if np.any(np.abs(x) > 1.0):
        raise ValueError(
            f"{what} must lie in [-1, 1]; got values in [{x.min():.3g}, {x.max():.3g}]"
        )


class VocalTract:
    """The agent's vocal tract.

    exact=False uses the fast formant map; exact=True the exact path, whose failed frames
    (VTL error, no resonance) get `sim.vocal.formants.FALLBACK_HZ` and are counted in
    `n_fallbacks`.
    """

    def __init__(
        self,
        exact: bool = False,
        config: VoiceConfig = DEFAULT_VOICE,
        world: WorldConfig = DEFAULT_WORLD,
        articulators: ArticulatorModel | None = None,
        formant_map: FormantMap | None = None,
    ) -> None:
        self.exact = exact
        self.config = config
        self.world = world
        self.articulators = default_articulators() if articulators is None else articulators
        self.formant_map = default_formant_map() if formant_map is None else formant_map
        self.n_fallbacks = 0  # exact-path frames that got the fallback value
        self._sample_idx = np.array(SAMPLE_INDICES)

    def formants(self, artic: np.ndarray) -> np.ndarray:
        """Articulator values (..., 7) in [-1, 1] -> (..., 2) log2 Hz (F1, F2)."""
        artic = np.asarray(artic, dtype=float)
        if artic.ndim == 0 or artic.shape[-1] != N_ARTICULATORS:
            raise ValueError(
                f"articulators must have shape (..., {N_ARTICULATORS}); got {artic.shape}"
            )
        _check_box(artic, "articulators")
        if not self.exact:
            return self.formant_map(artic)
        log2_hz, ok = tract_formants(self.articulators.to_tract(artic))
        self.n_fallbacks += int(np.size(ok) - np.count_nonzero(ok))
        return log2_hz

    def trajectory(self, m: np.ndarray) -> np.ndarray:
        """28 voice parameters in [-1, 1] -> (7, n_steps) articulator trajectory."""
        m = np.asarray(m, dtype=float)
        if m.shape != (VOICE_DIM,):
            raise ValueError(f"voice command must have shape ({VOICE_DIM},); got {m.shape}")
        _check_box(m, "voice command")
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

        Only the 5 sample steps go through the formant model.
        """
        traj = self.trajectory(m)
        return normalise(self.formants(traj[:, self._sample_idx].T), self.config)

    def recognise(self, features: np.ndarray) -> str | None:
        """The word heard in a (10,) sound, or None (see `sim.vocal.words.recognise`)."""
        return recognise(features, self.config)
