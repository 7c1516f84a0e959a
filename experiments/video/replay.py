"""Videos of a trial's iterations, by replaying the trial from its start.

A trial is deterministic given its config: the same agent and room, seeded the same way, make
the same proposals and the same feedback. Replaying from iteration 0 to the chosen iterations
(without filming the others) therefore reproduces them exactly; each filmed iteration's events
are checked against the trial's log, and any difference is reported, not hidden.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from experiments.analysis.logs import read_log
from experiments.run.trial_parts import fresh_trial_parts, log_row
from experiments.trial_dir.log_schema import ITERATION, STICK_GRASPED, TOY_MOVED_BY, WORD_RECOGNISED
from experiments.trial_dir.reading import open_for_reading
from experiments.video.episodes import (
    EpisodeRenderer,
    check_output_path,
    film_iteration,
    tract_audio,
)
from experiments.video.recording import parse_size
from learner.agent import Proposal
from models.layout import MODELS
from models.world import Feedback


class ReplayError(Exception):
    """A trial or a choice of iterations that cannot be replayed; the message says why."""


@dataclass
class ReplayedIteration:
    iteration: int
    logged: dict
    replayed: dict

    @property
    def matches(self) -> bool:
        return self.logged == self.replayed


def highlights(log: pd.DataFrame) -> dict[str, int]:
    """The first iteration of each notable event in a trial's log: a hand grasp (a toy moved by
    the hand), the first stick grasp, a toy caught by the stick, and a recognised word with the
    caregiver bringing the toy."""
    toy_by = {
        by: (log[list(TOY_MOVED_BY)] == by).any(axis=1) for by in ("hand", "stick", "caregiver")
    }
    wanted = {
        "hand grasp": toy_by["hand"],
        "first tool use": log[STICK_GRASPED],
        "toy caught by the stick": toy_by["stick"],
        "word brings a toy": toy_by["caregiver"] & (log[WORD_RECOGNISED] != ""),
    }
    found = {}
    for name, mask in wanted.items():
        hits = log[ITERATION][mask]
        if len(hits):
            found[name] = int(hits.iloc[0])
    return found


def _goal_block(model: int | None) -> str | None:
    """The sensory block a model's goal lives in, for drawing it."""
    return None if model is None else MODELS[model].sensory_block


def render_trial(
    trial_dir: str | os.PathLike,
    out_path: str | os.PathLike,
    iterations: Iterable[int] | None = None,
    use_highlights: bool = False,
    size: str | tuple[int, int] = "640x480",
    fps: float = 50.0,
    camera: str = "top",
    progress: bool = True,
) -> tuple[Path, list[ReplayedIteration]]:
    """Film chosen iterations of a trial (or its highlights) into one MP4 with sound.

    Returns the MP4's path and, per filmed iteration, its logged and replayed log rows.
    """
    trial_dir = Path(trial_dir)
    trial = open_for_reading(trial_dir)
    if not trial.has_config():
        raise ReplayError(trial.no_trial_line())
    out = check_output_path(out_path)
    size = parse_size(size)
    log = read_log(trial_dir)
    if log.empty:
        raise ReplayError(f"{trial_dir} has no logged iterations yet (no checkpoint)")
    if use_highlights:
        chosen = highlights(log)
        if not chosen:
            raise ReplayError(f"{trial_dir}: no highlight in {len(log)} iterations")
        wanted = sorted(set(chosen.values()))
    else:
        wanted = sorted(set(int(i) for i in (iterations or [])))
        if not wanted:
            raise ReplayError("choose iterations (--iterations I,J,...) or --highlights")
        bad = [i for i in wanted if not 0 <= i < len(log)]
        if bad:
            raise ReplayError(
                f"iterations {bad} are out of range: the trial logged 0..{len(log) - 1}"
            )
    config = trial.config()
    agent, room = fresh_trial_parts(config)
    voice_audio, word_audio = tract_audio(room)
    logged_rows = log.set_index(ITERATION)
    results: list[ReplayedIteration] = []
    bar = tqdm(total=wanted[-1] + 1, disable=not progress, desc="replay", unit="it")
    with EpisodeRenderer(size, fps, camera) as renderer:
        for it in range(wanted[-1] + 1):
            if it in wanted:

                def filmed(proposal: Proposal, it: int = it) -> Feedback:
                    return film_iteration(
                        renderer,
                        room,
                        proposal.motor_space,
                        proposal.m,
                        voice_audio=voice_audio,
                        word_audio=word_audio,
                        model=None if proposal.model is None else f"{proposal.model + 1}",
                        goal=proposal.goal,
                        goal_block=_goal_block(proposal.model),
                        iteration=it,
                    )

                proposal, context, feedback = agent.play(room, act=filmed)
                replayed = log_row(it, proposal, feedback, context)
                # The events' columns: the log's other columns (its source, the learner's
                # goal and interests) are not what filming could change.
                row = {ITERATION: it, **logged_rows.loc[it].to_dict()}
                # What the trial did not record (written before a column existed) is None.
                logged = {k: None if pd.isna(row.get(k)) else row.get(k) for k in replayed}
                results.append(ReplayedIteration(it, logged, replayed))
            else:
                agent.play(room)
            bar.update(1)
        bar.close()
        path = renderer.write(out)
    return path, results
