"""The opening paragraph of the report and the comparison pages: what the experiment is, what
the tests are, the rings in metres and what normalised competence means, for a reader who has
not read the paper. Its numbers come from the trials' own settings, like every figure's."""

from __future__ import annotations

from typing import Any

import numpy as np

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.report.pages import FEW_TRIALS

# Who can bring a toy of each ring to the base, in the rings' order (sim/config.py's toy_rings:
# hand reach, stick reach, beyond both).
RING_MEANS = (
    "within the hand's reach",
    "beyond the hand, within the stick's reach",
    "beyond both: only the caregiver can bring it",
)


def rings_text(config: dict, geometry: Geometry) -> list[str]:
    """The trials' rings as text ("ring 1: 0–0.5 m (within the hand's reach)"); what each
    means is said only for the study's three rings, at the hand's and the stick's reach."""
    rings = [tuple(map(float, r)) for r in config["world"]["toy_rings"]]
    limits = [geometry.hand_limit, geometry.stick_limit]
    study_layout = len(rings) == 3 and bool(np.allclose([r[1] for r in rings[:2]], limits))
    texts = []
    for i, (low, high) in enumerate(rings):
        text = f"ring {i + 1}: {low:g}–{high:g} m"
        if study_layout:
            text += f" ({RING_MEANS[i]})"
        texts.append(text)
    return texts


def page_context(results: BatchResults, geometry: Geometry) -> dict[str, Any]:
    """The template's keys for the opening paragraph (macros.html.j2, `intro`)."""
    config = next(iter(results.configs.values()))
    sizes = results.trials.groupby("group", sort=False).size()
    few = [
        f"{group} ({n} trial{'s' if n != 1 else ''})"
        for group, n in sizes.items()
        if n < FEW_TRIALS
    ]
    return {
        # Groups too small for their intervals: a visible warning above the first table.
        "intro_few": ", ".join(few),
        "intro_few_trials": FEW_TRIALS,
        "intro_rings": rings_text(config, geometry),
        "intro_hand": f"{geometry.hand_limit:g}",
        "intro_stick": f"{geometry.stick_limit - geometry.hand_limit:g}",
        "intro_placements": int(results.trials["n_placements"].iloc[0]),
    }
