"""The study's random reference (experiments/measure/study_measure.py) played in chunks, on a
pool of processes: a physical movement costs milliseconds, and the study's 30000 commands per
ring x 3 rings took minutes per group on one core.

Each ring's commands are cut into chunks of a fixed size; a chunk draws from its own generator,
seeded by (the reference's seed, ring index, chunk index), and is played from a fresh room of
the group's settings (its own room seed drawn from that generator). So the rows depend on the
settings alone, never on the number of processes or the order in which they finish. Within a
chunk the scene carries over as the study's notebook did (the toys re-placed every 3 commands,
the stick where the last command left it, moved toys staying moved until then); across chunks
it does not: each starts from the room's start pose, a departure from one stream per ring that
changes the reference's numbers once, not its kind.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Iterable
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass

import numpy as np
import pandas as pd
from tqdm import tqdm

from experiments.measure.evaluation import goal_trajectory
from experiments.run.trial_parts import fresh_trial_parts
from models.layout import MOTOR_DIMS, TOYS, block_slice, context_indices

# Commands per chunk: a multiple of 3 (each placement tests every toy) dividing the study's
# 30000, so that a group is 60 chunks of a few seconds each. Many chunks keep every core busy
# to the end; a fresh room per chunk (about 0.1 s) stays a few percent of its time.
CHUNK_COMMANDS = 1500
# Below this many commands in all, the reference is played in this process: a pool's processes
# each import MuJoCo and the room's compiled kernels first (seconds), more than they would save.
POOL_MIN_COMMANDS = 3000


@dataclass(frozen=True)
class Chunk:
    group: str
    ring: int  # index into the world's toy_rings
    index: int  # chunk number within the ring: its commands start at index * chunk size
    commands: int


def ring_placement(ring: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    """(3, 2) toys uniform in the ring (the study's `reset_toys(region)`: no clearance)."""
    radius = rng.uniform(*ring, size=len(TOYS))
    angle = rng.uniform(0.0, 2 * np.pi, size=len(TOYS))
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)


def chunks_of(
    group: str, rings: int, commands_per_ring: int, chunk_commands: int = CHUNK_COMMANDS
) -> list[Chunk]:
    """A group's chunks, ring by ring; the last of a ring holds what is left."""
    if chunk_commands < 1:
        raise ValueError(f"chunk_commands must be positive, got {chunk_commands}")
    return [
        Chunk(group, ring, k, min(chunk_commands, commands_per_ring - start))
        for ring in range(rings)
        for k, start in enumerate(range(0, commands_per_ring, chunk_commands))
    ]


def play_chunk(config: dict, seed: int, chunk: Chunk) -> pd.DataFrame:
    """One row per random command of the chunk: x, y of the goal toy and the error read on
    toy 1 (the notebook's, whatever the goal toy), from a fresh room of `config`."""
    rng = np.random.default_rng([seed, chunk.ring, chunk.index])
    # The room's own draws (the caregiver's place and words) get a seed of the chunk too:
    # rooms of one seed would repeat one caregiver sequence in every chunk.
    room_seed = int(rng.integers(2**31))
    _, room = fresh_trial_parts({**config, "trial": {**config["trial"], "seed": room_seed}})
    ring = room.config.toy_rings[chunk.ring]
    x, y, error = (np.empty(chunk.commands) for _ in range(3))
    for k in range(chunk.commands):
        if k % len(TOYS) == 0:
            room.arrange(toys=ring_placement(ring, rng))
        toy = TOYS[k % len(TOYS)]
        x[k], y[k] = room.context()[list(context_indices(toy))]
        space = "arm" if rng.random() < 0.5 else "voice"
        s = room.act(space, rng.uniform(-1, 1, MOTOR_DIMS[space])).s
        error[k] = np.linalg.norm(s[block_slice("toy1")] - goal_trajectory(np.array([x[k], y[k]])))
    return pd.DataFrame({"x": x, "y": y, "error": error})


def default_workers() -> int:
    """The machine's cores, as `playroom batch` counts them for its local workers."""
    return os.cpu_count() or 1


def play_references(
    configs: dict[str, dict],
    seed: int,
    commands_per_ring: int,
    workers: int | None = None,
    progress: bool | None = None,
    chunk_commands: int = CHUNK_COMMANDS,
) -> dict[str, pd.DataFrame]:
    """The reference of each group of `configs` (group -> a trial's config), its chunks in
    order, every group's chunks on one pool of `workers` processes (default: the cores). A
    group whose config makes no room is left out. progress: one bar of every chunk's commands
    on stderr (None: only on a terminal)."""
    chunks = []
    for group, config in configs.items():
        try:  # built here once, to read its rings and to leave out what makes no room
            _, room = fresh_trial_parts(config)
        except ValueError:
            continue
        rings = len(room.config.toy_rings)
        chunks += chunks_of(group, rings, commands_per_ring, chunk_commands)
    workers = min(workers or default_workers(), len(chunks))
    total = sum(c.commands for c in chunks)
    bar = tqdm(
        total=total,
        disable=None if progress is None else not progress,
        desc=f"study reference {', '.join(dict.fromkeys(c.group for c in chunks))}".rstrip(),
        unit="command",
    )
    with bar:
        if workers <= 1 or total < POOL_MIN_COMMANDS:
            played = {}
            for c in chunks:
                played[c] = play_chunk(configs[c.group], seed, c)
                bar.update(c.commands)
        else:
            played = _played_on_a_pool(configs, seed, chunks, workers, bar)
    return {
        group: pd.concat([played[c] for c in chunks if c.group == group], ignore_index=True)
        for group in dict.fromkeys(c.group for c in chunks)
    }


def _played_on_a_pool(
    configs: dict[str, dict], seed: int, chunks: Iterable[Chunk], workers: int, bar: tqdm
) -> dict[Chunk, pd.DataFrame]:
    # Fresh interpreters ("spawn"), as Dask's workers and the benchmarks' are: nothing of this
    # process (threads, an imported GL library) is inherited; MUJOCO_GL is, by the environment.
    context = multiprocessing.get_context("spawn")
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_stop_at_ctrl_c)
    try:
        futures: dict[Future[pd.DataFrame], Chunk] = {
            pool.submit(play_chunk, configs[c.group], seed, c): c for c in chunks
        }
        played = {}
        for future in as_completed(futures):
            chunk = futures[future]
            played[chunk] = future.result()
            bar.update(chunk.commands)
        return played
    finally:
        # On an error or Ctrl-C, chunks not yet started are dropped, not played to the end.
        pool.shutdown(cancel_futures=True)


def _stop_at_ctrl_c() -> None:
    """A worker stops at once at Ctrl-C (the terminal sends it to every process of the
    command): raised as KeyboardInterrupt in a worker, it would end only the chunk being
    played, and the worker would play the one queued behind it before the pool shut down."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
