"""`playroom bench`: speed figures measured side by side in one run.

Each figure is printed as `name: value unit`, one per line, so runs can be compared with diff.
Ratios are what to compare across machines; absolute times are printed beside them.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Iterator

import numpy as np

from experiments.bench.idle import idle_figures
from experiments.bench.names import ON_REQUEST, SECTION_NAMES
from experiments.bench.tracking import hand_tracking_errors
from experiments.bench.trials import (
    replication_pair_seconds,
    replication_trial_seconds,
    trial_seconds_per_iteration,
)
from models.layout import ARM_DIM, N_STEPS, SAMPLE_INDICES
from sim import Playroom
from sim.grasping.names import GRASPS
from sim.mujoco_import import mujoco
from sim.physics import CONTROL_SUBSTEPS

# Targets of the trial and learner figures (ratios to 500 bare mj_step; ms; s; minutes), on
# both CPU classes (experiments/bench/cpu_classes.py).
TRIAL_TARGETS = {"kinematic": 0.25, "physical": 1.4}
LEARNER_TARGET_MS = 0.25
TRIAL_80000_TARGET_S = 20.0  # a kinematic trial of 80000 iterations on one core
REPLICATION_TARGET_MIN = 20.0  # the replication profile on 2 cores
# The sections measured again under the emulated CPU class, in a second process.
EMULATED_SECTIONS = ("trial", "learner")
LEARNER_SIZES = (10000, 40000, 80000)
TRIAL_RUNS = 3  # runs of each short trial, the fastest kept (see trial_figures)


_CALL_ROUNDS = 4  # rounds of _seconds_per_call: one untimed, then the best of 3


def _seconds_per_call(fn: Callable[[], object], repeats: int) -> float:
    """Best of 3 rounds of `repeats` calls, after one untimed round: the least disturbed by
    other work on the machine. (The first round of bare steps from a fresh room ran up to 1.5
    times slower than the later ones on a 2-core virtual machine, and was often the best of
    three when timed.)"""
    for _ in range(repeats):
        fn()
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(repeats):
            fn()
        best = min(best, (time.perf_counter() - start) / repeats)
    return best


def world_figures(iterations: int = 100, seed: int = 0) -> Iterator[tuple[str, float, str]]:
    """Cost of an arm iteration in each backend against bare mj_step calls on the same model."""
    rng = np.random.default_rng(seed)
    commands = rng.uniform(-1.0, 1.0, (iterations, ARM_DIM))
    cost = {}
    # The physical room as trials run it and tracing its movements (as videos and Gymnasium's
    # frames do, sim/movement.py): what the trace costs.
    for name, grasp, tracing in (
        ("physical", "physical", False),
        ("physical_traced", "physical", True),
        ("kinematic", "kinematic", False),
    ):
        room = Playroom(grasp=grasp, seed=seed)
        room.tracing = tracing
        # Each call plays the next command (every round's worth of them).
        play_next = functools.partial(next, map(room.act_arm, np.tile(commands, (_CALL_ROUNDS, 1))))
        cost[name] = _seconds_per_call(play_next, iterations)
    m, d = _bare_physics(seed)
    n_steps = N_STEPS * CONTROL_SUBSTEPS
    bare = _seconds_per_call(lambda: mujoco.mj_step(m, d, n_steps), iterations)
    yield "physical_arm_iteration", cost["physical"] * 1e3, "ms"
    yield f"bare_mj_step_x{n_steps}", bare * 1e3, "ms"
    yield "physical_arm_iteration_over_bare_mj_step", cost["physical"] / bare, "ratio"
    yield (
        "physical_arm_iteration_traced_over_untraced",
        cost["physical_traced"] / cost["physical"],
        "ratio",
    )
    yield "kinematic_arm_iteration", cost["kinematic"] * 1e3, "ms"
    yield "kinematic_over_physical", cost["kinematic"] / cost["physical"], "ratio"
    yield from idle_figures(seed)


def tracking_figures(n_commands: int = 1000) -> Iterator[tuple[str, float, str]]:
    errors = hand_tracking_errors(n_commands)
    yield "hand_tracking_error_mean", errors.mean() * 1e3, f"mm over {n_commands} commands"
    yield "hand_tracking_error_max", errors.max() * 1e3, "mm"


def voice_figures(repeats: int = 20) -> Iterator[tuple[str, float, str]]:
    """The fitted formant map against the exact path, and the vocal part of an iteration."""
    from models.layout import VOICE_DIM
    from sim.dmp import voice_trajectory
    from sim.vocal.diva.data import DivaDataError, DivaDataMissing
    from sim.vocal.diva.tract import DivaTract
    from sim.vocal.voice import Voice
    from sim.vocal.vtl.tract import VocalTract
    from sim.vocal.words import normalise

    rng = np.random.default_rng(0)
    frames = rng.uniform(-1.0, 1.0, (repeats, 7))
    fast, exact = VocalTract(exact=False), VocalTract(exact=True)
    frame = iter(np.tile(frames, (_CALL_ROUNDS, 1)))
    exact_s = _seconds_per_call(lambda: exact.formants(next(frame)), repeats)
    # The learning loop sends a movement's 50 frames through the map at once.
    movements = iter(rng.uniform(-1.0, 1.0, (_CALL_ROUNDS * repeats, 50, 7)))
    fast_s = _seconds_per_call(lambda: fast.formants(next(movements)), repeats) / 50
    yield "formants_exact_per_frame", exact_s * 1e3, "ms"
    yield "formants_fast_map_per_frame", fast_s * 1e6, "us (in a movement of 50 frames)"
    yield "fast_map_speedup", exact_s / fast_s, "x (target >= 1000)"
    samples = list(SAMPLE_INDICES)

    def vocal_part_s(tract: Voice) -> float:
        # What act_voice does with the voice: the DMP, the formants of the 50 frames (the
        # sound sensor's readings), and the caregiver hearing the 5 samples.
        commands = iter(
            np.random.default_rng(1).uniform(-1.0, 1.0, (_CALL_ROUNDS * repeats, VOICE_DIM))
        )

        def vocal_part() -> None:
            formants = tract.formants(voice_trajectory(next(commands)).T)
            tract.recognise(normalise(formants[samples]))

        return _seconds_per_call(vocal_part, repeats)

    vtl_s = vocal_part_s(fast)
    yield "act_voice_vocal_part", vtl_s * 1e3, "ms (target <= 0.5)"
    try:
        diva: Voice | None = DivaTract(world=fast.world)
    except (DivaDataMissing, DivaDataError):
        diva = None
    if diva is None:
        yield "act_voice_vocal_part_diva", math.nan, "ms (not measured: DIVA's map not installed)"
    else:
        # Side by side in one run: DIVA's closed-form map against VTL's fast path.
        diva_s = vocal_part_s(diva)
        yield "act_voice_vocal_part_diva", diva_s * 1e3, "ms"
        yield "diva_over_vtl_vocal_part", diva_s / vtl_s, "ratio (same commands, same run)"
    room = Playroom("kinematic", seed=0)
    voice = iter(rng.uniform(-1.0, 1.0, (_CALL_ROUNDS * repeats, VOICE_DIM)))
    yield (
        "act_voice_kinematic_iteration",
        _seconds_per_call(lambda: room.act_voice(next(voice)), repeats) * 1e3,
        "ms",
    )


def learner_figures(sizes: tuple[int, ...] = LEARNER_SIZES) -> Iterator[tuple[str, float, str]]:
    """The memory's query against brute force, and the learner's own cost per iteration with
    every model holding 10000, 40000 and 80000 experiences."""
    from experiments.bench import learner as learner_bench

    largest = max(sizes)
    query = learner_bench.query_ratio(n_rows=largest)
    worst = max(query["by_dim"].values(), key=lambda d: d["memory_s"] / d["brute_s"])
    yield f"inverse_query_over_brute_force_at_{largest}_rows", query["ratio"], "ratio"
    yield "inverse_query", worst["memory_s"] * 1e6, "us"
    yield "brute_force_scan", worst["brute_s"] * 1e6, "us"
    for n_rows, seconds in learner_costs(sizes).items():
        target = f" (target <= {LEARNER_TARGET_MS})" if n_rows == largest else ""
        yield f"learner_per_iteration_at_{n_rows}_rows", seconds * 1e3, f"ms{target}"
    yield "peak_memory_with_all_models_full", _peak_rss_mb(), "MB (target < 1024)"


def learner_costs(sizes: tuple[int, ...]) -> dict[int, float]:
    """Seconds per iteration of propose + learn with every model holding n rows, per n; the
    experiences come from the study's kinematic world, whose own time is not counted."""
    from experiments.bench import learner as learner_bench

    return {
        n: learner_bench.learner_overhead(Playroom("kinematic", seed=1), n_rows=n)["mean_s"]
        for n in sizes
    }


def trial_figures(iterations: int = 5000) -> Iterator[tuple[str, float, str]]:
    """Whole trials of both backends side by side, against 500 bare mj_step on the same
    model (the fastest of TRIAL_RUNS runs of each, in turns); the replication's own trial,
    measured whole; the profiles' times from them."""
    from experiments.batches.spec import load_spec
    from learner.indexed_screen import warm_up

    # The memory's compiled kernel loads once per process (a batch worker runs many trials):
    # timed on its own, so the trials below measure iterations alone.
    start = time.perf_counter()
    warm_up()
    yield "memory_kernel_load_once_per_process", time.perf_counter() - start, "s"
    n_steps = N_STEPS * CONTROL_SUBSTEPS
    # The bare steps and the trials in turns, each the least disturbed of its runs: on a
    # shared virtual machine the same bare steps measured 2.5 ms and 3.9 ms a few minutes
    # apart, and the same physical trial 2.6 and 3.0 ms an iteration.
    bare_runs = [_bare_step_seconds(n_steps)]
    runs: dict[str, list[float]] = {grasp: [] for grasp in GRASPS}  # every registered one
    computed_share = math.nan  # the same in every run: the trial's numbers are
    for _ in range(TRIAL_RUNS):
        for grasp, times in runs.items():
            seconds, share = trial_seconds_per_iteration(grasp, iterations)
            times.append(seconds)
            if grasp == "physical":
                computed_share = share
        bare_runs.append(_bare_step_seconds(n_steps))
    bare = min(bare_runs)
    per_iteration = {grasp: min(times) for grasp, times in runs.items()}
    yield f"bare_mj_step_x{n_steps}", bare * 1e3, "ms"
    for grasp, seconds in per_iteration.items():
        yield f"{grasp}_trial_{iterations}", 1.0 / seconds, "iterations/s"
        target = TRIAL_TARGETS.get(grasp)
        yield (
            f"{grasp}_trial_iteration_over_bare_mj_step",
            seconds / bare,
            "ratio (no target set for this backend)"
            if target is None
            else f"ratio (target <= {target})",
        )
    yield (
        "physical_trial_control_steps_computed",
        computed_share,
        "share (the others found the room at rest: sim/compiled_steps.py)",
    )
    # The replication's own trial, measured whole (one core): its learner grows with its
    # memory, which the short trials above do not reach, and its models store what the study's
    # rules store, which no synthetic memory reproduces.
    replication = load_spec("replication")
    _, settings = replication.trials()[0]
    trial_s, evaluation_s = replication_trial_seconds(settings, replication.eval_placements)
    yield (
        f"kinematic_trial_{settings.iterations}",
        trial_s,
        f"s (target <= {TRIAL_80000_TARGET_S:g}, one core; the replication's trial)",
    )
    yield "evaluation_of_that_trial", evaluation_s, "s"
    # make replicate runs two trials at once on 2 cores, which share the machine's caches and
    # memory bandwidth: measured so, side by side.
    pair = replication_pair_seconds(
        [s for _, s in replication.trials()[:2]], replication.eval_placements
    )
    yield (
        f"kinematic_trial_{settings.iterations}_beside_another",
        float(np.mean([t for t, _ in pair])),
        "s (two of the replication's trials at once, one per core)",
    )
    n_trials = len(replication.trials())
    per_trial = float(np.mean([t + e for t, e in pair]))
    yield (
        "replication_profile_on_2_cores",
        n_trials * per_trial / 2 / 60,
        f"minutes ({n_trials} trials and evaluations, two at a time; target < "
        f"{REPLICATION_TARGET_MIN:g})",
    )
    # The paper profile's trials, projected: the kinematic one from the replication's whole
    # trial; every other backend's from its short trial's iterations plus the learner's growth
    # from 10000 to 40000 rows a model (its mean memory at 80000 iterations is at most 40000
    # rows a model).
    costs = learner_costs((10000, 40000))
    growth = max(0.0, costs[40000] - costs[10000])
    spec = load_spec("paper")
    by_grasp = {g: spec.iterations * (per_iteration[g] + growth) for g in per_iteration}
    by_grasp["kinematic"] = trial_s * spec.iterations / settings.iterations
    yield "physical_trial_80000_projected", by_grasp["physical"] / 3600, "h (one core)"
    total = sum(by_grasp[g] for g in spec.grasps) * len(spec.seeds) * len(spec.babbling)
    for cores in (1, 16, 100):
        yield f"paper_profile_on_{cores}_cores", total / cores / 3600, "h (running, projected)"


def _bare_physics(seed: int = 0) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The model and data of a fresh physical room, for bare steps: the physics alone, its
    sensors off. (The grasp's contact sensors, added to the model after the ratios' targets
    were set, cost 5% of a bare step; a trial computes them once a control step, at its last
    MuJoCo step.)"""
    room = Playroom(grasp="physical", seed=seed)
    m, d = room.physics.model.ptr, room.physics.data.ptr
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    return m, d


def _bare_step_seconds(n_steps: int) -> float:
    """Seconds of `n_steps` bare mj_step calls in a fresh physical room (`_bare_physics`)."""
    m, d = _bare_physics()
    return _seconds_per_call(lambda: mujoco.mj_step(m, d, n_steps), 100)


def render_section() -> Iterator[tuple[str, float, str]]:
    """Offscreen rendering speed (needs an OpenGL backend: the CLI chooses it before the
    rendering modules are imported)."""
    from experiments.bench.render import render_figures

    yield from render_figures()


def emulated_section(
    sections: tuple[str, ...] = EMULATED_SECTIONS,
) -> Iterator[tuple[str, float, str]]:
    """The trial and learner sections again, in a process that emulates the other CPU class
    (or, where that cannot be emulated, the next older one): figures named emulated_<class>_."""
    import subprocess
    import sys

    from experiments.bench import cpu_classes

    cpu = cpu_classes.emulated_class()
    print(f"emulated: {cpu.description}: {cpu_classes.shell_assignments(cpu)}", flush=True)
    if cpu_classes.this_class() is cpu_classes.WITHOUT_AVX512:
        print("emulated: (a CPU without AVX-512 cannot emulate one with it)", flush=True)
    command = [sys.executable, "-m", "experiments.cli.main", "bench", *sections]
    env = cpu_classes.emulation_environment(cpu)
    with subprocess.Popen(command, env=env, stdout=subprocess.PIPE, text=True) as child:
        assert child.stdout is not None  # asked for with stdout=PIPE
        for line in child.stdout:
            name, _, rest = line.partition(": ")
            value, _, unit = rest.strip().partition(" ")
            if name.startswith("machine"):
                print(f"emulated {line.strip()}", flush=True)
                continue
            yield f"emulated_{cpu.name}_{name}", float(value), unit
    if child.returncode != 0:
        raise RuntimeError(f"the emulated bench failed (exit code {child.returncode})")


def long_section() -> Iterator[tuple[str, float, str]]:
    """One trial of 10^6 iterations (experiments/bench/long.py)."""
    from experiments.bench.long import long_figures

    yield from long_figures()


def machine_line() -> str:
    """Which machine and which kernels the figures come from."""
    from experiments.bench import cpu_classes
    from experiments.trial_dir import provenance

    blas = ", ".join(f"{b['library']} {b['kernel']}" for b in provenance.blas_record())
    simd = provenance.simd_record()
    found = set(simd["dispatched"]) | set(simd["baseline"])
    top = [f for f in ("X86_V4", "X86_V3", "X86_V2") if f in found]
    return (
        f"machine: {provenance.cpu_model()} ({'with' if cpu_classes.has_avx512() else 'without'} "
        f"AVX-512); NumPy {top[0] if top else 'baseline'}; {blas}; numba "
        f"{provenance.numba_target()}"
    )


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


SECTIONS: dict[str, Callable[[], Iterator[tuple[str, float, str]]]] = {
    "trial": trial_figures,
    "learner": learner_figures,
    "world": world_figures,
    "tracking": tracking_figures,
    "voice": voice_figures,
    "render": render_section,
    "emulated": emulated_section,
    "long": long_section,
}

# The command line's list (experiments/bench/names.py) names exactly these, in this order.
if tuple(SECTIONS) != SECTION_NAMES:
    raise RuntimeError(f"experiments/bench/names.py lists {SECTION_NAMES}, not {tuple(SECTIONS)}")


def run_bench(sections: list[str] | None = None) -> None:
    """Print every figure of the chosen sections (all by default)."""
    print(machine_line(), flush=True)
    for name in sections or [s for s in SECTIONS if s not in ON_REQUEST]:
        for figure, value, unit in SECTIONS[name]():
            print(f"{figure}: {value:.4g} {unit}", flush=True)
