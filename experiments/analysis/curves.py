"""What a trial's logs say over time: developmental curves and the stick as a tool.

Curves are rates in windows of iterations (about CURVE_POINTS per trial, a multiple of 50
iterations each), in a long table (iteration, metric, value):
- tool_use: share of arm movements in which the stick moved a toy (a toy caught);
- stick_grasp: share of arm movements in which the hand took the stick;
- word_recognised: share of vocal movements in which the caregiver recognised a word;
- stick_in_reach: share of iterations that began with the stick's handle within the study's
  reach (arm length plus the world's grasp distance: one yardstick for every backend,
  experiments/trial_dir/backend_record.py `study_reach`); stick_returned: share of iterations after
  which the experimenter returned the stick (a trial written before these columns existed
  recorded neither: it has no such curves, and its stick numbers are NaN);
- best_distance_names, best_distance_distractors: mean best distance so far of the trial's
  names and distractors, wherever the words log has a row.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from experiments.trial_dir.log_schema import (
    ITERATION,
    MOTOR_SPACE,
    STICK_DISTANCE,
    STICK_GRASPED,
    STICK_RETURNED,
    TOY_MOVED_BY,
    WORD_RECOGNISED,
    recorded,
    word_columns,
)

CURVE_POINTS = 40
# Metric -> the column of movements it is a share of.
RATES = {
    "tool_use": "arm",
    "stick_grasp": "arm",
    "word_recognised": "voice",
    "stick_in_reach": "all",
    "stick_returned": "all",
}
# The iterations log's columns `curve_rows` and `tool_numbers` read (a reader may read only
# these: experiments/analysis/logs.read_log's `columns`).
LOG_COLUMNS = (
    ITERATION,
    MOTOR_SPACE,
    STICK_GRASPED,
    WORD_RECOGNISED,
    STICK_DISTANCE,
    STICK_RETURNED,
    *TOY_MOVED_BY,
)
# The columns of stick_in_reach and stick_returned, which older trials did not record.
STICK_COLUMNS = (STICK_DISTANCE, STICK_RETURNED)


def _events(log: pd.DataFrame, reach: float) -> pd.DataFrame:
    """Per iteration: arm, voice, all, and each metric of RATES (bool)."""
    arm = log[MOTOR_SPACE] == "arm"
    voice = log[MOTOR_SPACE] == "voice"
    frame = pd.DataFrame(
        {
            "arm": arm,
            "voice": voice,
            "all": True,
            "tool_use": (log[list(TOY_MOVED_BY)] == "stick").any(axis=1) & arm,
            "stick_grasp": log[STICK_GRASPED].astype(bool) & arm,
            "word_recognised": (log[WORD_RECOGNISED] != "") & voice,
        }
    )
    # Only where every row recorded them: a stretch without would read as never in reach.
    if recorded(log, STICK_COLUMNS):
        frame["stick_in_reach"] = log[STICK_DISTANCE] <= reach
        frame["stick_returned"] = log[STICK_RETURNED].astype(bool)
    return frame


def curve_rows(
    log: pd.DataFrame, words: pd.DataFrame, iterations: int, names: set[str], reach: float
) -> pd.DataFrame:
    """A trial's curves (module docstring) from its iterations and words logs; `reach` (m)."""
    window = max(50, round(iterations / CURVE_POINTS / 50) * 50)
    frame = _events(log, reach)
    frame["end"] = np.minimum((log[ITERATION].to_numpy() // window + 1) * window, iterations)
    sums = frame.groupby("end").sum()
    parts = []
    # A window without arm (or voice) movements has no rate: NaN, not a division warning.
    with np.errstate(invalid="ignore", divide="ignore"):
        for metric, base in RATES.items():
            if metric in sums.columns:
                value = (sums[metric] / sums[base].replace(0, np.nan)).to_numpy()
                parts.append(
                    pd.DataFrame({"iteration": sums.index, "metric": metric, "value": value})
                )
    if not words.empty:
        # A word never approached has distance inf; it would make every mean inf.
        values = words[word_columns(words)].replace(np.inf, np.nan)
        for metric, chosen in (
            ("best_distance_names", [w for w in values.columns if w in names]),
            ("best_distance_distractors", [w for w in values.columns if w not in names]),
        ):
            means = values[chosen].mean(axis=1)
            parts.append(
                pd.DataFrame({"iteration": words[ITERATION], "metric": metric, "value": means})
            )
    return pd.concat(parts, ignore_index=True)


def tool_numbers(log: pd.DataFrame, reach: float) -> dict[str, float]:
    """A whole trial's stick numbers: stick grasps and toy catches per 1000 arm movements, the
    share of iterations that began with the stick within reach, and the experimenter's returns
    (NaN where the log predates the column)."""
    frame = _events(log, reach)
    arms = max(1, int(frame["arm"].sum()))
    has_stick = "stick_in_reach" in frame.columns
    return {
        "stick_grasps_per_1000_arm": 1000 * frame["stick_grasp"].sum() / arms,
        "toy_catches_per_1000_arm": 1000 * frame["tool_use"].sum() / arms,
        "stick_in_reach": float(frame["stick_in_reach"].mean()) if has_stick else np.nan,
        "stick_returns": float(frame["stick_returned"].sum()) if has_stick else np.nan,
    }


def grasp_rate_by_distance(log: pd.DataFrame, bin_width: float = 0.01) -> pd.DataFrame:
    """How often the hand takes the stick against where the stick lies: per bin [low, high)
    of the handle's distance from the arm's base when an arm movement began (`stick_distance`,
    the context's), the arm movements begun there (`iterations`), those that took the stick
    (`grasps`) and their share (`rate`); bins without a movement are left out. Arm movements
    only: the physical hand grasps in no other, and the study's kinematic rule of the resting
    hand in vocal movements is not reaching. `log`: one trial's iterations log, or several
    concatenated (rows of trials written before `stick_distance` cannot say where the stick lay:
    they are left out)."""
    if bin_width <= 0:
        raise ValueError(f"bin_width must be positive, got {bin_width!r}")
    arm = log[(log[MOTOR_SPACE] == "arm") & log[STICK_DISTANCE].notna()]
    index = np.floor(arm[STICK_DISTANCE].to_numpy(dtype=float) / bin_width).astype(int)
    grouped = arm[STICK_GRASPED].astype(bool).groupby(index)
    table = pd.DataFrame({"iterations": grouped.size(), "grasps": grouped.sum().astype(int)})
    table["rate"] = table["grasps"] / table["iterations"]
    table.insert(0, "low", table.index * bin_width)
    table.insert(1, "high", (table.index + 1) * bin_width)
    return table.reset_index(drop=True)


def falling_rate_distance(
    rates: pd.DataFrame, start: float, fraction: float = 0.5, min_iterations: int = 100
) -> float:
    """The near edge of the first bin of `grasp_rate_by_distance` beyond the one holding
    `start` (the stick's start distance, m) whose rate is below `fraction` of that bin's:
    where the arm, as it learned to move, stops reaching the stick. Bins of fewer than
    `min_iterations` movements are too noisy to decide and are passed over. NaN when no bin
    falls so low, or the start's bin is too small."""
    at_start = rates[(rates["low"] <= start) & (start < rates["high"])]
    if at_start.empty or at_start["iterations"].iloc[0] < min_iterations:
        return float("nan")
    floor = fraction * float(at_start["rate"].iloc[0])
    beyond = rates[(rates["low"] > start) & (rates["iterations"] >= min_iterations)]
    below = beyond[beyond["rate"] < floor]
    return float(below["low"].iloc[0]) if not below.empty else float("nan")
