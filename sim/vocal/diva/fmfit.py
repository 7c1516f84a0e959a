"""DIVA's forward map, 'audsom' mode: articulators -> formants F1-F3 in Hz.

As `diva_synth.m` computes it (the early-2017 version the study ran; docs/protocol.md D13):
every articulator goes through tanh first; of the 13, the 10 vocal-tract articulators x drive
the formants. Each of the K mixture components has a centre mu_k and a shared inverse covariance
S; its weight is w_k proportional to p_k exp(-(x - mu_k) S (x - mu_k)' / 2), normalised over k
(the largest exponent subtracted first, as DIVA does, so that none overflows). The formants are
beta_fmt times the column-major vector of the K x 11 matrix w' [x, 1], i.e.

    F_f = sum_k sum_j beta_fmt[f, j K + k] w_k [x, 1]_j.

No formant is refused: a component's linear map can give F1 <= 0 Hz, and DIVA returns it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

N_VOCAL_TRACT = 10  # DIVA's articulators 1-10 shape the tract; 11-13 are F0, pressure, voicing
N_FORMANTS = 3


@dataclass(frozen=True)
class FormantFit:
    """DIVA's fitted map `fmfit`: mu (K, 10), i_sigma (10, 10), p (K,), beta_fmt (3, 11 K)."""

    mu: np.ndarray
    i_sigma: np.ndarray
    p: np.ndarray
    beta_fmt: np.ndarray
    _beta_by_component: np.ndarray = field(init=False, repr=False, compare=False)
    _mu_i_sigma: np.ndarray = field(init=False, repr=False, compare=False)
    _mu_i_sigma_mu: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        k = self.mu.shape[0] if self.mu.ndim == 2 else -1
        shapes = {
            "mu": (k, N_VOCAL_TRACT),
            "iSigma": (N_VOCAL_TRACT, N_VOCAL_TRACT),
            "p": (k,),
            "beta_fmt": (N_FORMANTS, (N_VOCAL_TRACT + 1) * k),
        }
        arrays = {"mu": self.mu, "iSigma": self.i_sigma, "p": self.p, "beta_fmt": self.beta_fmt}
        for name, expected in shapes.items():
            if k < 1 or arrays[name].shape != expected:
                raise ValueError(
                    f"fmfit.{name} must have shape {expected} (K = {k} components); "
                    f"got {arrays[name].shape}"
                )
            if not np.all(np.isfinite(arrays[name])):
                raise ValueError(f"fmfit.{name} holds NaN or infinite values")
        # beta_fmt regrouped once as (K, 11 * 3): component k's linear maps, [x, 1] by formant,
        # so that a batch of frames costs one product (see `formants_hz`).
        per_component = self.beta_fmt.reshape(N_FORMANTS, N_VOCAL_TRACT + 1, k)
        object.__setattr__(
            self, "_beta_by_component", per_component.transpose(2, 1, 0).reshape(k, -1)
        )

        # The quadratic form expanded, x S x' - 2 x S mu_k' + mu_k S mu_k', with the terms of
        # the centres computed once: a batch's exponents in two products instead of one per
        # component (equal to DIVA's (x - mu_k) S (x - mu_k)' within 1e-13 for the study's map).
        mu_i_sigma = self.mu @ self.i_sigma
        object.__setattr__(self, "_mu_i_sigma", mu_i_sigma)
        object.__setattr__(self, "_mu_i_sigma_mu", np.sum(mu_i_sigma * self.mu, axis=1))

    @property
    def n_components(self) -> int:
        return int(self.mu.shape[0])

    def weights(self, x: np.ndarray) -> np.ndarray:
        """(n, 10) tract articulators (after tanh) -> (n, K) mixture weights, rows summing to 1."""
        x_i_sigma_x = np.sum((x @ self.i_sigma) * x, axis=1)
        exponent = -0.5 * (
            x_i_sigma_x[:, None] - 2.0 * (x @ self._mu_i_sigma.T) + self._mu_i_sigma_mu[None, :]
        )
        w = self.p[None, :] * np.exp(exponent - exponent.max(axis=1, keepdims=True))
        return w / w.sum(axis=1, keepdims=True)

    def formants_hz(self, x: np.ndarray) -> np.ndarray:
        """(..., 10) tract articulators after tanh -> (..., 3) F1, F2, F3 in Hz."""
        x = np.asarray(x, dtype=float)
        flat = x.reshape(-1, N_VOCAL_TRACT)
        w = self.weights(flat)
        xa = np.concatenate([flat, np.ones((len(flat), 1))], axis=1)  # [x, 1]
        maps = (w @ self._beta_by_component).reshape(len(flat), N_VOCAL_TRACT + 1, N_FORMANTS)
        hz = np.matmul(xa[:, None, :], maps)[:, 0, :]
        return hz.reshape(*x.shape[:-1], N_FORMANTS)
