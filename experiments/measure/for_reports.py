"""The room measures a report needs (experiments/analysis/room_measures.py), measured here."""

from __future__ import annotations

import functools
import os
from collections.abc import Iterable

from experiments.analysis.room_measures import RoomMeasures
from experiments.analysis.study_summary import RANDOM_COMMANDS_PER_RING
from experiments.measure.stick import batch_worlds, grasp_rates
from experiments.measure.study_measure import study_numbers
from experiments.measure.untrained import untrained_numbers


def room_measures(
    study_reference_commands: int = RANDOM_COMMANDS_PER_RING,
    workers: int | None = None,
    batch_dirs: Iterable[str | os.PathLike] = (),
) -> RoomMeasures:
    """The study's numbers against a reference of `study_reference_commands` random commands
    per ring (the study's 30000 by default), played on `workers` processes (default: the
    cores; the numbers are the same whatever their number), and the stick's grasp rates, each
    backend in the world its trials in `batch_dirs` ran in (`stick.batch_worlds`)."""
    return RoomMeasures(
        study_numbers=functools.partial(
            study_numbers,
            commands_per_ring=study_reference_commands,
            workers=workers,
            beside=untrained_numbers,
        ),
        grasp_rates=functools.partial(grasp_rates, worlds=batch_worlds(batch_dirs)),
    )
