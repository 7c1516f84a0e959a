"""The stick as a tool across the backends: what pushes it, how often it can be grasped.

- `push_sources`: plays a trial's first iterations (its agent and room, as `playroom run` would),
  looks at every control step of each movement in its trace, and attributes each push of the
  stick (it moved while the hand did not hold it) to what touched it: the hand, a toy the hand
  holds, a free toy.
- `grasp_rates`: the share of random arm commands that grasp the stick from its start pose, in
  each backend asked (every registered one by default), for the very same commands: how much
  harder contact grasping is than the study's distance rule. Each backend plays in the world
  its trials ran in (`batch_worlds`: their config.json's), whose DMP turns the commands into
  movements: the project's DMP and the study's grasp different shares of the same commands.
"""

from __future__ import annotations

import dataclasses
import os
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir import storage
from experiments.trial_dir.reading import open_for_reading, trials_in
from models.layout import ARM_DIM, N_STEPS, TOYS
from models.presets import DEFAULT_PRESET
from models.world import Feedback
from sim import Playroom
from sim import events as ev
from sim.config import WorldConfig, config_from_dict, world_preset
from sim.grasping.names import GRASPS

# What can touch the stick, as push_sources names it.
SOURCES = ("hand", "toy held by the hand", "free toy", "nothing")


def push_sources(seed: int, iterations: int, stick_return: str = "never") -> dict:
    """Per source of SOURCES, the number of pushes of the stick and their total displacement
    (m), over the first `iterations` of the physical trial of `seed`; and the last iteration in
    which the hand grasped the stick, and how far the handle lay from the base at the end."""
    config = full_config(TrialSettings(grasp="physical", seed=seed, stick_return=stick_return))
    agent, room = fresh_trial_parts(config)
    p = room.physics
    room.tracing = True
    stick_geoms = set(p.stick_geoms.tolist())
    toy_geom = {int(g): TOYS[i] for i, g in enumerate(p.toy_geoms)}

    def touching(feedback: Feedback) -> set[str]:
        """What touched the stick in some step of the movement, the hand not holding it."""
        taken = _first_step(feedback, ev.STICK_GRASPED)
        held_toy = next((e for e in feedback.events if e.kind == ev.TOY_GRASPED), None)
        # The toy she brings is carried above the table and touches nothing meanwhile.
        brought = {e.obj for e in feedback.events if e.kind == ev.WORD_RECOGNISED and e.obj}
        touched: set[str] = set()
        assert room.last_trace is not None  # the room traces
        for step, posed in room.last_trace.replayed(p):
            if step >= taken:
                break
            held = held_toy.obj if held_toy is not None and held_toy.step <= step else None
            for a, b in posed.touching_pairs():
                partner = b if a in stick_geoms else a if b in stick_geoms else None
                if partner is None:
                    continue
                if partner == p.hand_geom:
                    touched.add("hand")
                elif partner in toy_geom and toy_geom[partner] not in brought:
                    touched.add("toy held by the hand" if toy_geom[partner] == held else "free toy")
        return touched

    pushes: Counter[str] = Counter()
    moved: Counter[str] = Counter()
    last_grasp = -1
    for iteration in range(iterations):
        before = p.stick_handle()
        _, _, feedback = agent.play(room)
        if ev.STICK_GRASPED in feedback.kinds():
            last_grasp = iteration
        if any(e.kind == ev.STICK_MOVED and e.by == "push" for e in feedback.events):
            touched = touching(feedback)
            distance = float(np.linalg.norm(feedback.positions[-1, 1] - before))
            for source in touched or {"nothing"}:
                pushes[source] += 1
                # typeshed counts a Counter in ints; these are metres (a source never pushed
                # reads 0 all the same).
                moved[source] += distance / max(1, len(touched))  # type: ignore[assignment]
    return {
        "pushes": {s: pushes[s] for s in SOURCES},
        "pushed_metres": {s: moved[s] for s in SOURCES},
        "last_stick_grasp": last_grasp,
        "final_handle_distance": float(np.hypot(*p.stick_handle())),
    }


def _first_step(feedback: Feedback, kind: str) -> int:
    """The step of the movement's first event of `kind`, or one past its last step."""
    return next((e.step for e in feedback.events if e.kind == kind), N_STEPS + 1)


def batch_worlds(batch_dirs: Iterable[str | os.PathLike]) -> dict[str, dict]:
    """Grasp backend -> the world (config.json's "world", added settings filled in) of the
    first trial of the first batch directory given that ran it: the world `grasp_rates` plays
    that backend in. Trials whose config cannot be read are passed over (a report's reading
    of the batch names them)."""
    worlds: dict[str, dict] = {}
    for batch_dir in map(Path, batch_dirs):
        trials = trials_in(batch_dir) if batch_dir.is_dir() else []
        for trial_dir in trials:
            try:
                config = open_for_reading(trial_dir).config()
                worlds.setdefault(config["trial"]["grasp"], config["world"])
            except (OSError, storage.CorruptFileError, KeyError, TypeError, AttributeError):
                continue
    return worlds


def grasp_rates(
    n_commands: int = 1000,
    grasps: Sequence[str] = GRASPS,
    seed: int = 0,
    progress: bool | None = None,
    worlds: Mapping[str, dict] | None = None,
) -> dict[str, float]:
    """Share of random arm commands that grasp the stick, per backend of `grasps`, each
    command from the same scene: the stick at its start pose, the toys where the room's seed
    placed them. Each backend plays in the world `worlds` gives it (config.json's "world" of
    the trials that ran it: `batch_worlds`), else in the default preset's (what `Playroom()`
    builds), with the experimenter's stick return off. A backend's share does not depend on
    which others are measured beside it. progress: a bar on stderr (None: only on a
    terminal)."""
    from tqdm import tqdm

    bar = tqdm(
        total=n_commands * len(grasps),
        disable=None if progress is None else not progress,
        desc="grasp rates",
        unit="command",
    )
    rng = np.random.default_rng(seed)
    commands = rng.uniform(-1.0, 1.0, (n_commands, ARM_DIM))
    rates = {}
    for grasp in grasps:
        given = (worlds or {}).get(grasp)
        world = (
            world_preset(DEFAULT_PRESET) if given is None else config_from_dict(WorldConfig, given)
        )
        config = dataclasses.replace(world, stick_return="never")
        start = (*config.stick_start_handle, config.stick_start_angle)
        room = Playroom(grasp, seed=seed, config=config)
        toys = room.context()[2:8].reshape(3, 2)
        grasped = 0
        for m in commands:
            room.arrange(stick=start, toys=toys)
            grasped += ev.STICK_GRASPED in room.act("arm", m).kinds()
            bar.update(1)
        rates[grasp] = grasped / n_commands
    bar.close()
    return rates
