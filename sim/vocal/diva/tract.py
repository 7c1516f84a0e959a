"""`DivaTract`: DIVA's vocal tract as the study used it ("diva" in models/tracts.py).

The study's code (c1c9c2d, environment/diva/diva.py; docs/protocol.md D13) fed DIVA 13
articulators per frame: its 7 vocal DMP dimensions, clipped to [-1, 1], drive DIVA's articulators
1-7; articulators 8-10 stay 0; F0, pressure and voicing (11-13) stay 1; the whole frame is
doubled before `diva_synth(..., 'audsom')`, which takes tanh of every articulator
(sim/vocal/diva/fmfit.py). Of DIVA's auditory output it kept F1 and F2 as log2 Hz, and a frame
whose formant is not positive (log2 gives NaN) became 0, i.e. a sound feature of -offset: no
frame is refused and none is counted as a fallback. Its vowel targets are the study's Hz values
(`VoiceConfig.study_vowel_hz`), with no re-targeting.
"""

from __future__ import annotations

import numpy as np

from models.layout import N_ARTICULATORS
from sim.config import DEFAULT_WORLD, WorldConfig
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.diva.data import DivaDataError, DivaDataMissing, installed_fit, map_digest
from sim.vocal.diva.fmfit import N_VOCAL_TRACT, FormantFit
from sim.vocal.diva.sound import SOUND_LABEL, synthesise_formants
from sim.vocal.voice import Voice

N_DIVA_ARTICULATORS = 13
INPUT_GAIN = 2.0  # the study doubled every articulator before DIVA
FIXED_SOURCE = 1.0  # F0, pressure and voicing articulators (11-13), before the gain
# A word said by the caregiver has only F1 and F2 targets; her F3 is held here (Hz), about
# where DIVA's map puts it for the study's vowels.
CAREGIVER_F3_HZ = 2500.0


def diva_input(artic: np.ndarray) -> np.ndarray:
    """(..., 7) frames in [-1, 1] -> (..., 13) articulators after DIVA's tanh."""
    frames = np.zeros((*artic.shape[:-1], N_DIVA_ARTICULATORS))
    frames[..., :N_ARTICULATORS] = artic
    frames[..., N_VOCAL_TRACT:] = FIXED_SOURCE
    return np.tanh(INPUT_GAIN * frames)


def source_f0_hz() -> float:
    """F0 in DIVA's auditory output for the study's fixed F0 articulator: 100 + 50 a11 Hz."""
    return 100.0 + 50.0 * float(np.tanh(INPUT_GAIN * FIXED_SOURCE))


class DivaTract(Voice):
    """The study's vocal tract: DIVA's fitted formant map (the user's installed data).

    fit: the map; the installed one (`sim.vocal.diva.data.installed_fit`) when None, whose
    absence stops here with DivaDataMissing, never falling back to another tract. exact is
    accepted for the common signature and changes nothing: DIVA's map is its only path.
    """

    name = "diva"
    sound_label = SOUND_LABEL
    user_data_errors = (DivaDataMissing, DivaDataError)

    def __init__(
        self,
        exact: bool = False,
        config: VoiceConfig = DEFAULT_VOICE,
        world: WorldConfig = DEFAULT_WORLD,
        fit: FormantFit | None = None,
    ) -> None:
        self.fit = installed_fit() if fit is None else fit
        super().__init__(exact, config, world)

    def data_record(self) -> dict[str, str]:
        """The map's digest (sim/vocal/diva/data.py): which DIVA map the trial ran."""
        return {"diva_map": map_digest(self.fit)}

    def formants_hz(self, artic: np.ndarray) -> np.ndarray:
        """(..., 7) checked frames -> (..., 3) DIVA's F1-F3 in Hz (any sign)."""
        return self.fit.formants_hz(diva_input(artic)[..., :N_VOCAL_TRACT])

    def frame_formants(self, artic: np.ndarray) -> np.ndarray:
        hz = self.formants_hz(artic)[..., :2]
        with np.errstate(invalid="ignore", divide="ignore"):
            log2_hz = np.log2(hz)
        # The study's rule for a formant that is not positive: NaN (and -inf) become 0.
        return np.where(np.isfinite(log2_hz), log2_hz, 0.0)

    def vowel_targets(self) -> dict[str, np.ndarray]:
        return {
            v: np.log2(np.array(self.config.study_hz(v), dtype=float)) for v in self.config.vowels
        }

    def audio(self, artic_traj: np.ndarray) -> tuple[np.ndarray, int]:
        """The formant synthesizer at DIVA's F1-F3 of each step (sim/vocal/diva/sound.py)."""
        return synthesise_formants(self.formants_hz(np.asarray(artic_traj).T), source_f0_hz())

    def word_audio(self, word: str) -> tuple[np.ndarray, int]:
        """The caregiver's word: the formant synthesizer along its 5 target points."""
        log2_hz = self.word_trajectory(word)  # (5, 2)
        hz = np.column_stack([2.0**log2_hz, np.full(len(log2_hz), CAREGIVER_F3_HZ)])
        return synthesise_formants(hz, source_f0_hz())
