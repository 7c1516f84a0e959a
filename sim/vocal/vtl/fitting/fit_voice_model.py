"""Regenerate the voice's data files in sim/vocal/vtl/data/ (seeded; `make voice-model`).

    python -m sim.vocal.vtl.fitting.fit_voice_model [--samples N] [--seed S] [--workers W]
        [--max-iter I]

1. articulators.npz: PCA articulators of the VTL speaker; prints the explained variance.
2. vowels.npz: vowel targets (exact path on the speaker's vowel shapes), printed beside the
   study's Hz values.
3. formant_map.npz: the fast map, an MLP fitted on N exact-path samples (half uniform in the
   articulator box, half uniform in a 1.25x larger box clipped back to it, because DMP
   trajectories often saturate at the faces). Prints the median and 95th-percentile absolute
   error per formant on a separate uniform held-out sample of N // 10 articulations.
4. productions.npz: the best voice parameters for each word and their distances.

The exact path runs in `--workers` processes (each process has its own VocalTractLab state).
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time

import numpy as np
from tqdm import tqdm

from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.vtl.articulators import ArticulatorModel, build_articulator_model
from sim.vocal.vtl.formant_map import ROUNDS, FormantMap, fit_formant_map
from sim.vocal.vtl.formants import tract_formants
from sim.vocal.vtl.produce import compute_productions, save_productions
from sim.vocal.vtl.tract import VocalTract
from sim.vocal.vtl.words import (
    compute_vowel_targets,
    recognise,
    save_vowel_targets,
    word_features,
)

CHUNK = 100  # articulations per worker task

_worker_model: ArticulatorModel | None = None


def _init_worker(model: ArticulatorModel) -> None:
    global _worker_model
    _worker_model = model


def _exact_chunk(artic: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    assert _worker_model is not None
    return tract_formants(_worker_model.to_tract(artic))


def exact_formants_parallel(
    model: ArticulatorModel, artic: np.ndarray, workers: int, desc: str
) -> tuple[np.ndarray, np.ndarray]:
    """Exact-path log2 formants (N, 2) and ok flags (N,) of articulations (N, 7)."""
    chunks = np.array_split(artic, max(1, len(artic) // CHUNK))
    with mp.get_context("fork").Pool(workers, _init_worker, (model,)) as pool:
        results = list(
            tqdm(pool.imap(_exact_chunk, chunks), total=len(chunks), desc=desc, unit="chunk")
        )
    return np.concatenate([r[0] for r in results]), np.concatenate([r[1] for r in results])


def sample_box(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 7) articulations: half uniform in [-1, 1]^7, half clipped from [-1.25, 1.25]^7."""
    half = n // 2
    uniform = rng.uniform(-1.0, 1.0, (half, 7))
    faces = np.clip(rng.uniform(-1.25, 1.25, (n - half, 7)), -1.0, 1.0)
    return np.vstack([uniform, faces])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=30000, help="exact-path training samples")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2, help="processes for the exact path")
    parser.add_argument("--max-iter", type=int, default=3000, help="L-BFGS iterations of the MLP")
    parser.add_argument(
        "--words-only",
        action="store_true",
        help="keep the stored articulators and fast map; redo vowel targets and productions",
    )
    args = parser.parse_args(argv)
    t_start = time.perf_counter()
    rng_art, rng_train, rng_test = np.random.default_rng(args.seed).spawn(3)
    cfg = DEFAULT_VOICE

    # 1. Articulators.
    if args.words_only:
        model = ArticulatorModel.load()
    else:
        model = build_articulator_model(seed=int(rng_art.integers(2**31)))
        model.save()
    ev = model.explained_variance_ratio
    print("Articulators: 7 principal components of the speaker's tract shapes")
    print("  explained corpus variance per component:", np.round(ev, 4), f"(sum {ev.sum():.4f})")
    print(f"  variance of all 11 speaker vowels explained: {model.speaker_vowel_coverage:.4f}")
    print("  study vowels in articulator units (max |a| = 0.8 by construction):")
    for name, a in zip(model.vowel_names, model.vowel_articulators, strict=True):
        print(f"    /{name}/ {np.array2string(a, precision=2, suppress_small=True)}")

    # 2. Vowel targets.
    targets = compute_vowel_targets(cfg)
    save_vowel_targets(targets, cfg)
    print("Vowel targets (exact path on the speaker's shapes) vs the study's values:")
    print("  vowel   F1 Hz   F2 Hz   | study F1   F2")
    for name, t in zip(cfg.vowels, targets, strict=True):
        f1, f2 = 2.0**t
        s1, s2 = cfg.study_hz(name)
        print(f"  /{name}/  {f1:7.0f} {f2:7.0f}   | {s1:7.0f} {s2:5.0f}")

    # 3. Fast formant map.
    if args.words_only:
        fmap = FormantMap.load()
    else:
        n_test = max(200, args.samples // 10)
        x_train = sample_box(rng_train, args.samples)
        x_test = rng_test.uniform(-1.0, 1.0, (n_test, 7))
        t0 = time.perf_counter()
        y_train, ok_train = exact_formants_parallel(model, x_train, args.workers, "exact (train)")
        y_test, ok_test = exact_formants_parallel(model, x_test, args.workers, "exact (held-out)")
        t_gen = time.perf_counter() - t0
        print(
            f"Exact path: {len(x_train) + n_test} articulations in {t_gen:.0f} s; "
            f"fallbacks: {np.count_nonzero(~ok_train)} train, {np.count_nonzero(~ok_test)} held-out"
        )
        t0 = time.perf_counter()
        fmap = fit_formant_map(
            x_train[ok_train],
            y_train[ok_train],
            seed=args.seed,
            max_iter=args.max_iter,
            rounds=tqdm(range(ROUNDS), desc="MLP fit (L-BFGS)", unit="round"),
        )
        t_fit = time.perf_counter() - t0
        # Evaluate and use the map as stored (float32 weights), exactly as the world will load it.
        fmap.save()
        fmap = FormantMap.load()
        err = np.abs(fmap(x_test[ok_test]) - y_test[ok_test])
        med, p95 = np.median(err, axis=0), np.percentile(err, 95, axis=0)
        print(f"Fast map fitted in {t_fit:.0f} s. Held-out abs error (log2), F1 / F2:")
        print(f"  median {med[0]:.4f} / {med[1]:.4f}   (target <= 0.02)")
        print(f"  p95    {p95[0]:.4f} / {p95[1]:.4f}   (target <= 0.06)")
        fmap.save(samples=args.samples, seed=args.seed, heldout_median=med, heldout_p95=p95)

    # 4. Word productions, through the new fast map.
    tract = VocalTract(articulators=model, formant_map=fmap)
    params, dists = compute_productions(tract, seed=args.seed)
    save_productions(cfg.words, params, dists)
    exact = VocalTract(exact=True, articulators=model, formant_map=fmap)
    print("Word productions: distance to the word (fast map / exact path), heard as")
    for word, m, d in zip(cfg.words, params, dists, strict=True):
        fe = exact.sound_features(m)
        de = float(np.linalg.norm(fe - word_features(word)))
        print(f"  {word}: {d:.3f} / {de:.3f}  heard as {recognise(fe)}")
    print(f"Done in {time.perf_counter() - t_start:.0f} s.")


if __name__ == "__main__":
    main()
