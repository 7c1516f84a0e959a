"""Tests of the vocal tract (sim/vocal): articulators, exact and fast formants, words, audio."""

from __future__ import annotations

import numpy as np
import pytest
import vocaltractlab_cython as vtl

from sim.caregiver import assign_words
from sim.dmp import voice_trajectory
from sim.vocal.audio import write_wav
from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.vtl import formants as formants_mod
from sim.vocal.vtl.articulators import default_articulators, speaker_shapes
from sim.vocal.vtl.audio import synthesise
from sim.vocal.vtl.formants import FALLBACK_HZ, tract_formants, tube_formants
from sim.vocal.vtl.productions import say, stored_distances
from sim.vocal.vtl.tract import VocalTract
from sim.vocal.vtl.words import (
    recognise,
    vowel_targets,
    word_distances,
    word_features,
)


@pytest.fixture(scope="module")
def tract() -> VocalTract:
    return VocalTract()


@pytest.fixture(scope="module")
def exact_tract() -> VocalTract:
    return VocalTract(exact=True)


def test_vowels_inside_articulator_box_and_reproduced() -> None:
    art = default_articulators()
    assert art.components.shape == (7, 19)
    for name in DEFAULT_VOICE.vowels:
        a = art.vowel(name)
        assert np.all(np.abs(a) <= 0.8 + 1e-9), (name, a)  # 1.25x margin
        # The 8-shape corpus spans 7 dimensions, so the articulators reproduce the vowel.
        np.testing.assert_allclose(art.to_tract(a), speaker_shapes((name,))[0], atol=1e-9)


def test_articulators_batch_shapes_and_ranges() -> None:
    art = default_articulators()
    x = np.random.default_rng(0).uniform(-1, 1, (4, 50, 7))
    states = art.to_tract(x)
    assert states.shape == (4, 50, 19)
    assert np.all(states >= art.lo - 1e-12) and np.all(states <= art.hi + 1e-12)


def _random_lines(rng: np.random.Generator, n_lines: int, n_points: int) -> np.ndarray:
    """(n_lines, n_points, 7): chords of the box [-1, 1]^7 through a random inner point in a
    random direction, from face to face."""
    lines = []
    for _ in range(n_lines):
        p = rng.uniform(-1, 1, 7)
        d = rng.standard_normal(7)
        d /= np.linalg.norm(d)
        with np.errstate(divide="ignore"):
            t_hi = np.min(np.where(d > 0, (1 - p) / d, (-1 - p) / d))
            t_lo = np.max(np.where(d > 0, (-1 - p) / d, (1 - p) / d))
        t = np.linspace(t_lo, t_hi, n_points)
        lines.append(np.clip(p + t[:, None] * d, -1, 1))
    return np.array(lines)


def test_exact_path_continuous_along_lines() -> None:
    art = default_articulators()
    lines = _random_lines(np.random.default_rng(2024), n_lines=10, n_points=60)
    log2_hz, ok = tract_formants(art.to_tract(lines))
    assert np.all(ok)
    steps = np.abs(np.diff(log2_hz, axis=1))  # (10, 59, 2)
    assert steps.max() <= 0.2, steps.max(axis=(0, 1))


def _vtl_peaks(state: np.ndarray) -> np.ndarray:
    """First two peaks (Hz) of VTL's transfer-function magnitude, 8192 samples."""
    n = 8192
    mag = vtl.tract_state_to_transfer_function(state, n_spectrum_samples=n)["magnitude_spectrum"]
    rate = vtl.get_constants()["sr_audio"]
    peak = np.nonzero((mag[1:-1] > mag[:-2]) & (mag[1:-1] > mag[2:]))[0] + 1
    return peak[:2] * rate / n


@pytest.mark.parametrize("vowel", DEFAULT_VOICE.vowels)
def test_exact_formants_agree_with_vtl_peaks(vowel: str) -> None:
    state = speaker_shapes((vowel,))[0]
    log2_hz, ok = tract_formants(state)
    assert ok
    peaks = _vtl_peaks(state)
    rel = np.abs(2.0**log2_hz / peaks - 1.0)
    assert np.all(rel <= 0.15), (vowel, 2.0**log2_hz, peaks)


def test_vowel_targets_are_exact_path_of_speaker_vowels() -> None:
    stored = vowel_targets()
    for name in DEFAULT_VOICE.vowels:
        log2_hz, _ = tract_formants(speaker_shapes((name,))[0])
        np.testing.assert_allclose(stored[name], log2_hz, atol=1e-9)


def test_fast_map_accuracy_on_fresh_exact_sample(tract: VocalTract) -> None:
    # A seed the fit script never uses, uniform in the box: 600 points (about 2 s of exact
    # path) give the median and the 95th percentile to within a few thousandths.
    x = np.random.default_rng(987654).uniform(-1, 1, (600, 7))
    exact, ok = tract_formants(tract.articulators.to_tract(x))
    err = np.abs(tract.formants(x[ok]) - exact[ok])
    median, p95 = np.median(err, axis=0), np.percentile(err, 95, axis=0)
    assert np.all(median <= 0.02), median
    assert np.all(p95 <= 0.06), p95


@pytest.mark.parametrize("word", DEFAULT_VOICE.words)
def test_every_word_producible(word: str, tract: VocalTract, exact_tract: VocalTract) -> None:
    m = say(word)
    fast = tract.sound_features(m)
    assert np.linalg.norm(fast - word_features(word)) <= 0.25
    assert np.isclose(
        np.linalg.norm(fast - word_features(word)), stored_distances()[word], atol=1e-4
    )
    assert tract.recognise(fast) == word
    # The exact path hears the same word (it is what the audio is made of).
    assert exact_tract.recognise(exact_tract.sound_features(m)) == word


def test_recognition() -> None:
    for word in DEFAULT_VOICE.words:
        assert recognise(word_features(word)) == word
        near = word_features(word) + 0.3 / np.sqrt(10)  # distance 0.3 from the word
        assert recognise(near) == word
    far = word_features("oey") + 1.0  # distance sqrt(10) from it, far from all words
    assert recognise(far) is None
    assert word_distances(np.stack([far, far])).shape == (2, 6)


def test_word_features_layout() -> None:
    t = vowel_targets()
    f = word_features("oey")
    np.testing.assert_allclose(f[0], t["o"][0] - 8.5)
    np.testing.assert_allclose(f[1], (t["o"][0] + t["e"][0]) / 2 - 8.5)
    np.testing.assert_allclose(f[4], t["y"][0] - 8.5)
    np.testing.assert_allclose(f[5], t["o"][1] - 10.25)
    np.testing.assert_allclose(f[9], t["y"][1] - 10.25)


def test_word_assignment_per_seed() -> None:
    a = assign_words(np.random.default_rng(3), DEFAULT_VOICE)
    b = assign_words(np.random.default_rng(3), DEFAULT_VOICE)
    assert a == b
    assert len(a.names) == 3 and len(a.distractors) == 3
    assert sorted(a.names + a.distractors) == sorted(DEFAULT_VOICE.words)
    assert a.toy_of(a.names[1]) == 1 and a.toy_of(a.distractors[0]) is None
    seen = {assign_words(np.random.default_rng(s), DEFAULT_VOICE).names for s in range(20)}
    assert len(seen) > 1


def test_sound_features_shapes_and_trajectory(tract: VocalTract) -> None:
    m = np.random.default_rng(1).uniform(-1, 1, 28)
    feats = tract.sound_features(m)
    assert feats.shape == (10,) and np.all(np.isfinite(feats))
    per_step = tract.trajectory_formants(voice_trajectory(m))
    assert per_step.shape == (50, 2)
    np.testing.assert_allclose(tract.features_from_formants(per_step), feats, atol=1e-12)


@pytest.mark.parametrize(
    "bad",
    [np.zeros(27), np.zeros((2, 28)), np.full(28, np.nan), np.full(28, 1.5), np.full(28, -np.inf)],
)
def test_bad_voice_command_raises(tract: VocalTract, bad: np.ndarray) -> None:
    with pytest.raises(ValueError):
        tract.sound_features(bad)


def test_bad_articulators_raise(tract: VocalTract) -> None:
    with pytest.raises(ValueError, match="shape"):
        tract.formants(np.zeros(6))
    with pytest.raises(ValueError, match="NaN"):
        tract.formants(np.array([np.nan] * 7))
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
        tract.formants(np.full(7, 1.01))
    with pytest.raises(ValueError, match="shape"):
        tract.trajectory_formants(np.zeros((50, 7)))


def test_fallback_on_closed_tract_is_finite_and_counted(monkeypatch) -> None:
    lengths = np.full((2, 40), 0.44)
    areas = np.full((2, 40), 3.0)
    areas[1, 20] = 0.0  # a closed tract (no minimum area): no resonance can be computed
    hz, ok = tube_formants(lengths, areas, min_area=0.0)
    assert ok.tolist() == [True, False]
    np.testing.assert_allclose(hz[1], FALLBACK_HZ)
    assert np.all(np.isfinite(hz))

    # With the default minimum area, the same closed tract stays open and has resonances.
    _, ok_open = tube_formants(lengths, areas)
    assert np.all(ok_open)

    def failing(*args, **kwargs):
        raise vtl.VtlApiError("simulated VTL failure")

    monkeypatch.setattr(formants_mod.vtl, "tract_state_to_tube_state", failing)
    exact = VocalTract(exact=True)
    out = exact.formants(np.zeros((3, 7)))
    np.testing.assert_allclose(out, np.log2(np.broadcast_to(FALLBACK_HZ, (3, 2))))
    assert exact.n_fallbacks == 3


def test_audio_synthesis_and_wav(tmp_path) -> None:
    art = default_articulators()
    traj = np.linspace(art.vowel("o"), art.vowel("i"), 50).T  # (7, 50)
    wave, rate = synthesise(traj, duration_s=0.25, pad_s=0.02)
    assert rate == 44100
    assert np.all(np.isfinite(wave)) and np.max(np.abs(wave)) > 1e-3
    assert abs(len(wave) / rate - 0.29) < 0.01
    path = tmp_path / "oi.wav"
    write_wav(path, wave, rate)
    from scipy.io import wavfile

    r, data = wavfile.read(path)
    assert r == rate and data.dtype == np.int16 and len(data) == len(wave)
