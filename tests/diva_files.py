"""DIVA files of DIVA's structure with made-up numbers: what the tests of the DIVA voice use,
since DIVA's own map is the user's (sim/vocal/diva/data.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.io

from sim.vocal.diva import data
from sim.vocal.diva.fmfit import FormantFit


def generated_fit(k: int = 5, seed: int = 0) -> FormantFit:
    """A map of DIVA's structure with made-up numbers: formants of a few hundred Hz."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(10, 10))
    beta = rng.normal(scale=60.0, size=(3, 11 * k))
    beta[:, 10 * k :] = [[500.0], [1500.0], [2500.0]]  # the constant terms: [x, 1]'s last
    return FormantFit(
        mu=rng.uniform(-1, 1, (k, 10)), i_sigma=a @ a.T / 10 + np.eye(10), p=rng.uniform(0.1, 1, k),
        beta_fmt=beta,
    )  # fmt: skip


def write_diva_file(path: Path, fit: FormantFit, flat: bool = False) -> Path:
    if flat:
        scipy.io.savemat(path, {
            "fmfit_mu": fit.mu, "fmfit_isigma": fit.i_sigma, "fmfit_p": fit.p[:, None],
            "fmfit_beta_fmt": fit.beta_fmt, "fmfit_beta_som": np.zeros((6, fit.beta_fmt.shape[1])),
        })  # fmt: skip
    else:
        struct = {
            "mu": fit.mu,
            "iSigma": fit.i_sigma,
            "p": fit.p[:, None],
            "beta_fmt": fit.beta_fmt,
        }
        scipy.io.savemat(path, {"fmfit": struct, "vt": {"Scale": np.ones(10)}})
    return path


@pytest.fixture
def installed_generated_map(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FormantFit:
    """A generated map installed as if it were the study's (the real file is not ours to ship)."""
    fit = generated_fit()
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path / "data"))
    monkeypatch.setattr(data, "STUDY_MAP_DIGEST", data.map_digest(fit))
    where, what = data.install(write_diva_file(tmp_path / "diva_synth.mat", fit))
    assert where == tmp_path / "data" / data.CACHE_NAME and "unlisted" in what
    return fit
