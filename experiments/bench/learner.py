"""Speed of the learner, for `playroom bench`: numbers returned, nothing printed.

- `query_ratio`: time of the memory's nearest-neighbour query divided by the brute-force NumPy
  scan of the same rows (`learner.memory.brute_force_nearest`), with the same answers asserted.
  Rows and queries are uniform in [-1, 1]^dim for each dimension of an inverse-model key of the
  10 models (10, 12, 14, 18): queries uniform in the box are the far-from-data goals of goal
  babbling. The screen's cost does not depend on how the rows are spread; the exact re-ranking
  after it grows with the rows lying within a grid step (1/127) of the nearest, usually one.
- `learner_overhead`: seconds per iteration of `propose` + `learn` (model choice, inverse
  query, noise, storing into every model of the motor space, interest update) when every model
  holds `n_rows` experiences, in the world the caller passes, whose time is excluded.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from learner.agent import Agent
from learner.config import LearnerConfig
from learner.memory import NearestNeighbourMemory, brute_force_nearest
from learner.sensorimotor_model import MODELS
from models.world import World

INVERSE_KEY_DIMS = tuple(sorted({len(spec.context_dims) + 10 for spec in MODELS}))


def query_ratio(
    n_rows: int = 80000,
    dims: tuple[int, ...] = INVERSE_KEY_DIMS,
    n_queries: int = 200,
    repeats: int = 3,
    seed: int = 0,
) -> dict[str, Any]:
    """{'ratio': worst ratio over dims, 'by_dim': {dim: {...}}}; AssertionError on a mismatch.

    Per dim: 'memory_s' and 'brute_s' are the best-of-`repeats` mean seconds per query.
    """
    rng = np.random.default_rng(seed)
    by_dim: dict[int, dict[str, float]] = {}
    for dim in dims:
        rows = rng.uniform(-1.0, 1.0, (n_rows, dim))
        memory = NearestNeighbourMemory(dim)
        for row in rows:  # grown one row at a time, as in a trial
            memory.append(row)
        queries = rng.uniform(-1.0, 1.0, (n_queries, dim))
        for q in queries:
            got, want = memory.nearest(q), brute_force_nearest(rows, q)
            assert got == want, f"dim {dim}: memory answered {got}, brute force {want}"
        memory_s, brute_s = np.inf, np.inf
        # Interleaved, so a busy machine slows both alike.
        for _ in range(repeats):
            start = time.perf_counter()
            for q in queries:
                memory.nearest(q)
            memory_s = min(memory_s, (time.perf_counter() - start) / n_queries)
            start = time.perf_counter()
            for q in queries:
                brute_force_nearest(rows, q)
            brute_s = min(brute_s, (time.perf_counter() - start) / n_queries)
        by_dim[dim] = {"memory_s": memory_s, "brute_s": brute_s, "ratio": memory_s / brute_s}
    return {
        "n_rows": n_rows,
        "ratio": max(d["ratio"] for d in by_dim.values()),
        "by_dim": by_dim,
    }


def learner_overhead(
    world: World,
    n_rows: int = 80000,
    n_iterations: int = 1000,
    babbling: str = "random",
    seed: int = 0,
) -> dict[str, Any]:
    """Seconds per iteration of the learner alone, every model holding `n_rows` experiences,
    playing in `world` (whose own time is not counted).

    Returns {'mean_s', 'median_s', 'p99_s', 'model_bytes', 'n_rows', 'babbling'}; model_bytes
    is what the 10 models' arrays hold after the run.
    """
    config = LearnerConfig(babbling=babbling)
    agent = Agent(config, rng=seed)
    for _ in range(config.n_bootstrap):  # the bootstrap, untimed
        agent.play(world)
    rng = np.random.default_rng(seed + 2)
    for model in agent.models:
        missing = n_rows - len(model)
        if missing > 0:  # experiences spread like goals; the scan's cost ignores their spread
            model.extend(
                rng.uniform(-1.0, 1.0, (missing, model.motor_dim)),
                rng.uniform(-1.0, 1.0, (missing, len(model.context_dims))),
                rng.uniform(-1.0, 1.0, (missing, model.sensory_dim)),
            )
    # Untimed first iterations: the first query loads (or compiles) the memory's kernel, once
    # per process, 0.2 to 0.7 s.
    _time_iterations(agent, world, np.empty(20))
    times = np.empty(n_iterations)
    _time_iterations(agent, world, times)
    return {
        "n_rows": n_rows,
        "babbling": babbling,
        "mean_s": float(times.mean()),
        "median_s": float(np.median(times)),
        "p99_s": float(np.quantile(times, 0.99)),
        "model_bytes": int(sum(model.nbytes() for model in agent.models)),
    }


def _time_iterations(agent: Agent, world: World, times: np.ndarray) -> None:
    """Fill `times` with the seconds of propose + learn of successive iterations."""
    for i in range(len(times)):
        context = world.context()
        start = time.perf_counter()
        proposal = agent.propose(context)
        elapsed = time.perf_counter() - start
        s = world.act(proposal.motor_space, proposal.m).s
        start = time.perf_counter()
        agent.learn(proposal, context, s)
        times[i] = elapsed + time.perf_counter() - start
