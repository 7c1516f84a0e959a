"""Random vocal commands against the words, in each vocal tract: how far babbling starts.

The paper's Fig. 1b: of 200 random vocal commands none sounded within the recognition distance
(0.4) of a word, and the best learned /uye/ came to 0.3. `random_sound_table` plays the same
kind of commands (uniform in [-1, 1]^28, through the study preset's vocal DMP) in each tract and
reports, per tract: the share within the recognition distance of any word, the median distance
to the nearest word, and for each word the best command's distance. Both tracts hear the same
commands, so the difference is the tract's.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from tqdm import tqdm

from models.layout import VOICE_DIM
from models.presets import DEFAULT_PRESET
from models.tracts import TRACTS
from sim.config import world_preset
from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.registry import make_tract


def random_sound_table(
    tracts: tuple[str, ...] = TRACTS, n_commands: int = 200, seed: int = 0, progress: bool = False
) -> pd.DataFrame:
    """One row per tract: n_commands, within_recognition (share), median_nearest, and
    best_<word> for each word. DivaDataMissing where DIVA's map is needed and not installed."""
    if isinstance(n_commands, bool) or not isinstance(n_commands, int) or n_commands <= 0:
        raise ValueError(f"n_commands must be a positive integer, got {n_commands!r}")
    unknown = [t for t in tracts if t not in TRACTS]
    if unknown or not tracts:
        raise ValueError(f"unknown vocal tracts {unknown}: choose from {', '.join(TRACTS)}")
    commands = np.random.default_rng(seed).uniform(-1.0, 1.0, (n_commands, VOICE_DIM))
    rows = []
    for name in tracts:
        world = world_preset(DEFAULT_PRESET, voice=name)
        tract = make_tract(name, False, DEFAULT_VOICE, world)
        bar = tqdm(commands, desc=f"random sounds ({name})", disable=not progress, unit="cmd")
        distances = np.stack([tract.word_distances(tract.sound_features(m)) for m in bar])
        nearest = distances.min(axis=1)
        row = {
            "tract": name,
            "n_commands": n_commands,
            "within_recognition": float(np.mean(nearest < DEFAULT_VOICE.recognition_distance)),
            "median_nearest": float(np.median(nearest)),
        }
        row |= {
            f"best_{w}": float(distances[:, i].min()) for i, w in enumerate(DEFAULT_VOICE.words)
        }
        rows.append(row)
    return pd.DataFrame(rows).set_index("tract")
