"""DIVA's vocal tract: its map against the equations, its data's checks, the study's use of it,
and, where the real file is installed, agreement with outputs DIVA itself produced."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.io
from diva_files import generated_fit, write_diva_file

from sim.config import world_preset
from sim.dmp import rollout
from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.diva import data
from sim.vocal.diva.fmfit import FormantFit
from sim.vocal.diva.sound import synthesise_formants
from sim.vocal.diva.tract import DivaTract

NOTEBOOK = Path(__file__).parents[2] / "data" / "diva-study-notebook.json"


def formants_by_the_equations(fit: FormantFit, x: np.ndarray) -> np.ndarray:
    """diva_synth_sample's 'audsom' lines, one frame at a time."""
    out = []
    for frame in x:
        s = np.array([-0.5 * (frame - m) @ fit.i_sigma @ (frame - m) for m in fit.mu])
        w = fit.p * np.exp(s - s.max())
        w = w / w.sum()
        px = np.outer(w, np.append(frame, 1.0))  # K x 11
        out.append(fit.beta_fmt @ px.flatten(order="F"))  # MATLAB's px(:) is column-major
    return np.array(out)


def test_the_map_is_diva_s_equations() -> None:
    fit = generated_fit()
    x = np.tanh(np.random.default_rng(1).uniform(-2, 2, (40, 10)))
    np.testing.assert_allclose(fit.formants_hz(x), formants_by_the_equations(fit, x), rtol=1e-10)
    w = fit.weights(x)
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    assert fit.formants_hz(x.reshape(4, 10, 10)).shape == (4, 10, 3)


def test_the_study_s_use_of_diva() -> None:
    """7 DMP articulators into DIVA's 1-7, 8-10 at 0, F0/pressure/voicing at 1, all doubled,
    then tanh; log2 F1, F2; a formant that is not positive gives 0; the study's vowels in Hz."""
    fit = generated_fit()
    tract = DivaTract(fit=fit, world=world_preset("study", voice="diva"))
    artic = np.random.default_rng(2).uniform(-1, 1, (6, 7))
    full = np.zeros((6, 13))
    full[:, :7], full[:, 10:] = artic, 1.0
    expected = np.log2(formants_by_the_equations(fit, np.tanh(2.0 * full)[:, :10])[:, :2])
    np.testing.assert_allclose(tract.formants(artic), expected, rtol=1e-10)
    negative = generated_fit()
    object.__setattr__(negative, "beta_fmt", -negative.beta_fmt)  # every F1 below 0 Hz
    negative.__post_init__()
    assert np.all(DivaTract(fit=negative).formants(artic) == 0.0)
    targets = tract.vowel_targets()
    assert set(targets) == set(DEFAULT_VOICE.vowels)
    np.testing.assert_allclose(2.0 ** targets["o"], [500.0, 900.0])
    o_e_y = tract.word_features("oey")
    assert tract.recognise(o_e_y) == "oey" and tract.recognise(o_e_y + 0.2) is None


def test_audio_sounds_at_the_formants() -> None:
    wave, rate = synthesise_formants(np.tile([700.0, 1200.0, 2600.0], (50, 1)), f0_hz=148.0)
    assert np.max(np.abs(wave)) == pytest.approx(1.0) and rate == 22050
    spectrum = np.abs(np.fft.rfft(wave * np.hanning(len(wave))))
    freqs = np.fft.rfftfreq(len(wave), 1 / rate)
    band = (freqs > 300) & (freqs < 1800)
    peak = freqs[band][np.argmax(spectrum[band])]
    assert abs(peak - 700.0) < 150.0  # the first formant's harmonics are the loudest there
    with pytest.raises(ValueError, match="shape"):
        synthesise_formants(np.zeros((5, 2)), 148.0)


def test_the_loader_reads_both_layouts_and_names_what_is_wrong(tmp_path: Path) -> None:
    fit = generated_fit()
    for flat in (False, True):
        read = data.read_fit(write_diva_file(tmp_path / f"d{flat}.mat", fit, flat))
        assert data.map_digest(read) == data.map_digest(fit)
    (tmp_path / "text.mat").write_text("not a mat file")
    with pytest.raises(data.DivaDataError, match="not a MATLAB .mat file"):
        data.read_fit(tmp_path / "text.mat")
    scipy.io.savemat(tmp_path / "other.mat", {"x": np.ones(3)})
    with pytest.raises(data.DivaDataError, match="holds no DIVA map"):
        data.read_fit(tmp_path / "other.mat")
    scipy.io.savemat(tmp_path / "partial.mat", {"fmfit": {"mu": fit.mu, "p": fit.p}})
    with pytest.raises(data.DivaDataError, match="lacks iSigma, beta_fmt"):
        data.read_fit(tmp_path / "partial.mat")
    bad = {"mu": fit.mu, "iSigma": fit.i_sigma, "p": fit.p, "beta_fmt": fit.beta_fmt[:, :-1]}
    scipy.io.savemat(tmp_path / "shape.mat", {"fmfit": bad})
    with pytest.raises(data.DivaDataError, match=r"beta_fmt must have shape \(3, 55\)"):
        data.read_fit(tmp_path / "shape.mat")
    with pytest.raises(data.DivaDataError, match="is not a file"):
        data.read_fit(tmp_path / "missing.mat")


def test_only_the_study_s_map_installs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path / "data"))
    other = write_diva_file(tmp_path / "other.mat", generated_fit(k=7))
    with pytest.raises(data.DivaDataError, match="unknown DIVA map with 7 components, not the"):
        data.install(other)
    assert not (tmp_path / "data").exists()  # nothing written
    with pytest.raises(data.DivaDataMissing, match="playroom voice-data diva PATH"):
        data.installed_fit()


def test_an_installed_map_is_read_back_and_a_damaged_one_refused(
    installed_generated_map: FormantFit,
) -> None:
    assert data.map_digest(data.installed_fit()) == data.map_digest(installed_generated_map)
    data.cache_path().write_bytes(data.cache_path().read_bytes()[:100])
    data._read_cache.cache_clear()
    with pytest.raises(data.DivaDataError, match="damaged"):
        data.installed_fit()


def real_fit() -> FormantFit:
    try:
        return data.installed_fit()
    except (data.DivaDataMissing, data.DivaDataError) as exc:
        pytest.skip(f"DIVA's own map is not installed here ({type(exc).__name__})")


def test_diva_itself_agrees_where_its_map_is_installed() -> None:
    """The study's notebook printed DIVA's formants of random commands (through Octave):
    our tract gives the same to the 8 decimals printed."""
    tract = DivaTract(fit=real_fit(), world=world_preset("study", voice="diva"))
    rows = json.loads(NOTEBOOK.read_text())["rows"]
    for row in rows:
        m = np.array(row["voice_command"])
        start, weights, goal = m[:7], m[7:21].reshape(7, 2) * 300.0, m[21:]
        traj = np.clip(rollout(start, goal, weights, 50, "study"), -1.0, 1.0)
        np.testing.assert_allclose(
            tract.formants(traj.T)[-1], row["last_frame_log2_f1_f2"], atol=1e-7
        )
