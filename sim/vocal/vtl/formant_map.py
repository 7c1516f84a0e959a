"""The fast formant map: 7 articulators -> (log2 F1, log2 F2), a small MLP run in plain NumPy.

Like DIVA's fitted formant model, a smooth map is fitted once (by `fit_voice_model`, with
scikit-learn) on a large sample of the exact path (`sim.vocal.vtl.formants`) and stored as weights
in data/formant_map.npz. Inference is a few matrix products: a (50, 7) batch costs a few tens of
microseconds, against about 5 ms per frame for the exact path.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DATA_FILE = Path(__file__).parent / "data" / "formant_map.npz"
HIDDEN_LAYERS = (64, 64)
ROUNDS = 20  # warm-started L-BFGS rounds of a fit, for progress reporting


@dataclass(frozen=True)
class FormantMap:
    """A tanh MLP: articulators (..., 7) in [-1, 1] -> log2 Hz (..., 2) = (F1, F2)."""

    weights: tuple[np.ndarray, ...]  # per layer (n_in, n_out)
    biases: tuple[np.ndarray, ...]  # per layer (n_out,)
    y_mean: np.ndarray  # (2,) log2 Hz: outputs are standardised during the fit
    y_std: np.ndarray  # (2,) log2 Hz

    def __call__(self, artic: np.ndarray) -> np.ndarray:
        """(..., 7) articulator values -> (..., 2) log2 Hz. No input checks (see VocalTract)."""
        h = np.asarray(artic, dtype=float)
        for w, b in zip(self.weights[:-1], self.biases[:-1], strict=True):
            h = np.tanh(h @ w + b)
        return (h @ self.weights[-1] + self.biases[-1]) * self.y_std + self.y_mean

    def at_rows(self, artic: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """`self(artic)[rows]`, the same numbers to the last bit, computing the tanh (most of
        the cost) of those rows only. artic (n, 7), rows (k,) -> (k, 2).

        Every matrix product still takes all n rows, the others zero: which BLAS kernel
        computes a row, hence its last bits, depends on the matrix's shape (OpenBLAS's Haswell
        kernel gives other bits to a row multiplied alone), never on the other rows' values.
        """
        h = np.asarray(artic, dtype=float)
        for w, b in zip(self.weights[:-1], self.biases[:-1], strict=True):
            z = h @ w
            h = np.zeros(z.shape)
            h[rows] = np.tanh(z[rows] + b)  # the bias too only where it is needed
        return ((h @ self.weights[-1])[rows] + self.biases[-1]) * self.y_std + self.y_mean

    def save(self, path: Path = DATA_FILE, **report: np.ndarray | float) -> None:
        """Write the weights, plus any fit report values (stored for the record)."""
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {f"w{i}": w.astype(np.float32) for i, w in enumerate(self.weights)}
        arrays |= {f"b{i}": b.astype(np.float32) for i, b in enumerate(self.biases)}
        # mypy checks the ** values against savez's allow_pickle: bool too (none is named so).
        np.savez(path, y_mean=self.y_mean, y_std=self.y_std, **arrays, **report)  # type: ignore[arg-type]

    @classmethod
    def load(cls, path: Path = DATA_FILE) -> FormantMap:
        with np.load(path) as d:
            n_layers = sum(1 for k in d.files if k.startswith("w"))
            # float64 at inference: float32 storage halves the file, the products stay exact
            # enough (1e-6 log2) and float64 avoids mixed-precision casts on every call.
            return cls(
                weights=tuple(d[f"w{i}"].astype(float) for i in range(n_layers)),
                biases=tuple(d[f"b{i}"].astype(float) for i in range(n_layers)),
                y_mean=d["y_mean"].astype(float),
                y_std=d["y_std"].astype(float),
            )


def fit_formant_map(
    artic: np.ndarray,
    log2_formants: np.ndarray,
    seed: int = 0,
    max_iter: int = 3000,
    rounds: Iterable[int] | None = None,
) -> FormantMap:
    """Fit the MLP on exact-path samples: artic (N, 7), log2_formants (N, 2) in log2 Hz.

    L-BFGS on the full batch: for a small smooth regression it reaches a lower error than Adam
    in the same time. The fit runs in rounds of max_iter // ROUNDS iterations (warm-started) so
    that a progress bar can wrap `rounds` (an iterable of ROUNDS items, e.g. tqdm(range(ROUNDS))).
    """
    # Fit-time only dependency: importing scikit-learn would slow down every world start.
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.neural_network import MLPRegressor

    y_mean = log2_formants.mean(axis=0)
    y_std = log2_formants.std(axis=0)
    per_round = max(1, max_iter // ROUNDS)
    mlp = MLPRegressor(
        hidden_layer_sizes=HIDDEN_LAYERS,
        activation="tanh",
        solver="lbfgs",
        alpha=1e-6,
        max_iter=per_round,
        max_fun=10 * per_round,
        tol=1e-10,
        warm_start=True,
        random_state=seed,
    )
    target = (log2_formants - y_mean) / y_std
    with warnings.catch_warnings():
        # Every round stops at its iteration limit on purpose.
        warnings.simplefilter("ignore", category=ConvergenceWarning)
        for _ in range(ROUNDS) if rounds is None else rounds:
            mlp.fit(artic, target)
    return FormantMap(
        weights=tuple(np.asarray(w, float) for w in mlp.coefs_),
        biases=tuple(np.asarray(b, float) for b in mlp.intercepts_),
        y_mean=y_mean,
        y_std=y_std,
    )


@functools.cache
def default_formant_map() -> FormantMap:
    """The stored fast map (data/formant_map.npz, written by fit_voice_model)."""
    if not DATA_FILE.exists():
        raise FileNotFoundError(
            f"{DATA_FILE} is missing: run `python -m sim.vocal.vtl.fitting.fit_voice_model` "
            "to build it"
        )
    return FormantMap.load(DATA_FILE)
