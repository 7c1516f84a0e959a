"""`VocalTract`: VocalTractLab's vocal tract ("vtl" in models/tracts.py), this project's.

The study ran DIVA (sim/vocal/diva/); this articulatory synthesizer is the project's own voice
and the default one (docs/protocol.md §7).

Articulator values (7 per frame) in [-1, 1] go to formants (log2 Hz) either through the fast
fitted map (default; microseconds per movement) or the exact path (VocalTractLab area function
and lossless-tube resonances; about 5 ms per frame). Audio is VocalTractLab's synthesis
(sim/vocal/vtl/audio.py). What the world does with formants is common to every tract
(sim/vocal/voice.py).
"""

from __future__ import annotations

import numpy as np

from sim.config import DEFAULT_WORLD, WorldConfig
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.voice import Voice
from sim.vocal.vtl.articulators import ArticulatorModel, default_articulators
from sim.vocal.vtl.audio import synthesise
from sim.vocal.vtl.formant_map import FormantMap, default_formant_map
from sim.vocal.vtl.formants import tract_formants
from sim.vocal.vtl.productions import synthesise_word
from sim.vocal.vtl.words import vowel_targets


class VocalTract(Voice):
    """The agent's vocal tract, VocalTractLab's.

    exact=False uses the fast formant map; exact=True the exact path, whose failed frames
    (VTL error, no resonance) get `sim.vocal.vtl.formants.FALLBACK_HZ` and are counted in
    `n_fallbacks`.
    """

    name = "vtl"
    sound_label = "sound: VocalTractLab"

    def __init__(
        self,
        exact: bool = False,
        config: VoiceConfig = DEFAULT_VOICE,
        world: WorldConfig = DEFAULT_WORLD,
        articulators: ArticulatorModel | None = None,
        formant_map: FormantMap | None = None,
    ) -> None:
        super().__init__(exact, config, world)
        self.articulators = default_articulators() if articulators is None else articulators
        self.formant_map = default_formant_map() if formant_map is None else formant_map

    def frame_formants(self, artic: np.ndarray) -> np.ndarray:
        if not self.exact:
            return self.formant_map(artic)
        log2_hz, ok = tract_formants(self.articulators.to_tract(artic))
        self.n_fallbacks += int(np.size(ok) - np.count_nonzero(ok))
        return log2_hz

    def frame_formants_at(self, artic: np.ndarray, rows: np.ndarray) -> np.ndarray | None:
        return None if self.exact else self.formant_map.at_rows(artic, rows)

    def vowel_targets(self) -> dict[str, np.ndarray]:
        """The speaker's own vowels (sim/vocal/vtl/words.py), not the study's Hz values."""
        return vowel_targets(self.config)

    def audio(self, artic_traj: np.ndarray) -> tuple[np.ndarray, int]:
        """VocalTractLab's synthesis of the trajectory, at the default duration and padding."""
        return synthesise(artic_traj, articulators=self.articulators)

    def word_audio(self, word: str) -> tuple[np.ndarray, int]:
        """The stored production of the word (sim/vocal/vtl/produce.py) through VocalTractLab."""
        return synthesise_word(word)
