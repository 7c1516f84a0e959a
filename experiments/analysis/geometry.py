"""The reach limits and recognition threshold a report draws with, read from the trials'
own settings."""

from __future__ import annotations

from dataclasses import dataclass

from experiments.analysis.results import BatchResults, ReportError


@dataclass(frozen=True)
class Geometry:
    """Reach limits and recognition threshold, read from the trials' own settings (not
    constants), so that a batch run with another arm or stick is reported on its own terms.

    hand_limit, stick_limit: distances from the arm's base (world units, the arm's full reach
    is 1); threshold: the caregiver's word-recognition distance; bootstrap: iterations of
    random babbling before learning (arm plus voice)."""

    hand_limit: float
    stick_limit: float
    threshold: float
    bootstrap: int

    @classmethod
    def of(cls, results: BatchResults) -> Geometry:
        config = next(iter(results.configs.values()))
        try:
            hand = float(sum(config["world"]["segment_lengths"]))
            stick = hand + float(config["world"]["stick_length"])
            threshold = float(config["voice"]["recognition_distance"])
            learner = config["learner"]
            bootstrap = int(learner["bootstrap_arm"]) + int(learner["bootstrap_voice"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ReportError(
                f"the trials' config.json lacks a setting the report needs ({exc})"
            ) from None
        return cls(hand, stick, threshold, bootstrap)
