"""What a report shows that only a room can measure: the study's numbers of a batch (its tests
pooled against a random reference played in a fresh room of the batch's settings) and the
grasp rates of random commands in each backend. The report stage reads results and builds no
room (docs/architecture.md): the measuring stage provides the two functions
(`experiments.measure.for_reports.room_measures`) and the command line hands them over."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from experiments.analysis.results import BatchResults


@dataclass(frozen=True)
class RoomMeasures:
    # `study_summary` of each group of a batch that holds the study's tests, by group.
    study_numbers: Callable[[BatchResults], dict[str, dict]]
    # Share of N random arm commands that grasp the stick at its start, in each of the named
    # backends, by backend.
    grasp_rates: Callable[[int, tuple[str, ...]], dict[str, float]]
