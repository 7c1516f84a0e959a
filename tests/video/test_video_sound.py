"""A video's sound and its file: clips mixed and levelled, the WAV writer, frames encoded and
muxed with the sound track and moved into place whole."""

from __future__ import annotations

import os

import imageio_ffmpeg
import numpy as np
import pytest
from scipy.io import wavfile
from video_checks import FPS, SIZE, decoded_frames, stream_listing, tone

from experiments.video import encoding, sound
from sim.vocal.audio import write_wav


def test_mix_audio_places_resamples_and_clips():
    ones = np.ones(800)  # 0.1 s at 8 kHz
    track = sound.mix_audio([(0.5, ones, 8000), (0.55, ones, 8000)], 1.0, 16_000, peak=None)
    assert track.shape == (16_000,) and track.dtype == np.float32
    assert np.all(track[:7_990] == 0) and np.all(track[10_500:] == 0)
    assert track[8_400] == pytest.approx(1.0, abs=0.05)  # one clip
    assert track[9_000] == 1.0  # two overlapping clips, clipped to full scale
    # Clips are brought to a common peak: a quiet babble is heard as well as a loud word.
    levelled = sound.mix_audio([(0.0, 0.002 * ones, 8000), (0.5, 0.2 * ones, 8000)], 1.0, 8000)
    assert levelled[400] == pytest.approx(sound.CLIP_PEAK)  # the quiet babble
    assert levelled[4400] == pytest.approx(sound.CLIP_PEAK)  # the loud word
    # A clip running past the end is cut, not an error.
    assert sound.mix_audio([(0.95, ones, 8000)], 1.0, rate=8000).shape == (8000,)
    with pytest.raises(ValueError, match="NaN"):
        sound.mix_audio([(0.0, np.array([np.nan]), 8000)], 1.0)


def test_wav_writer_round_trips_through_scipy(tmp_path):
    rate = 8000
    wave = np.array([0.0, 0.25, -0.5, 1.0, -1.0, 1.7, -3.0])
    path = tmp_path / "levels.wav"
    write_wav(path, wave, rate, peak=None)
    read_rate, pcm = wavfile.read(path)
    assert read_rate == rate and pcm.dtype == np.int16
    # Levels kept; beyond full scale clipped, not wrapped around to the other sign.
    np.testing.assert_array_equal(pcm, [0, 8192, -16384, 32767, -32767, 32767, -32767])
    # By default a lone sound is brought to 0.9 of full scale (`playroom say`).
    write_wav(path, 0.01 * np.sin(np.linspace(0, 20, 400)), rate)
    assert np.abs(wavfile.read(path)[1]).max() == round(0.9 * 32767)
    # Silence stays silence.
    write_wav(path, np.zeros(50), rate)
    assert not wavfile.read(path)[1].any()
    with pytest.raises(ValueError, match="NaN"):
        write_wav(path, np.array([0.0, np.nan]), rate)


def test_wav_writer_keeps_a_float32_track_exact(tmp_path):
    """The video's track is float32: its samples round as they did before the writers merged."""
    track = np.random.default_rng(1).uniform(-1.2, 1.2, 4000).astype(np.float32)
    write_wav(tmp_path / "t.wav", track, 8000, peak=None)
    expected = np.round(np.clip(track, -1.0, 1.0) * 32767).astype(np.int16)
    np.testing.assert_array_equal(wavfile.read(tmp_path / "t.wav")[1], expected)


def test_sound_track_is_mixed_and_written_at_its_rate(tmp_path):
    path = sound.write_track(tmp_path / "track.wav", [(0.25, *tone(0.2))], 1.0, rate=16_000)
    rate, pcm = wavfile.read(path)
    assert rate == 16_000 and pcm.shape == (16_000,)
    # The tone, resampled from 22.05 kHz, sits at 0.25-0.45 s at the clip peak, silence around.
    assert not pcm[: 4_000 - 10].any() and not pcm[7_200 + 10 :].any()
    assert np.abs(pcm[4_000:7_200]).max() == pytest.approx(sound.CLIP_PEAK * 32767, rel=0.02)


def test_encoded_frames_are_muxed_and_moved_into_place(tmp_path):
    scratch, target = tmp_path / "scratch", tmp_path / "out"
    scratch.mkdir(), target.mkdir()
    frames_file(scratch / "frames.mp4")
    assert imageio_ffmpeg.count_frames_and_secs(str(scratch / "frames.mp4"))[0] == 10
    sound.write_track(scratch / "sound.wav", [(0.0, *tone(0.1))], 11 / FPS)
    out = target / "video.mp4"
    out.write_bytes(b"an older video")
    assert encoding.mux_into_place(scratch / "frames.mp4", scratch / "sound.wav", out) == out
    assert decoded_frames(out).shape == (10, SIZE[1], SIZE[0], 3)
    assert "Audio:" in stream_listing(out)
    # Nothing left behind: the muxed file was moved, the temporary ones removed.
    assert os.listdir(target) == ["video.mp4"]
    assert sorted(os.listdir(scratch)) == ["frames.mp4", "sound.wav"]


def test_failed_mux_leaves_the_old_file_whole(tmp_path):
    out = tmp_path / "video.mp4"
    out.write_bytes(b"an older video")
    write_wav(tmp_path / "sound.wav", np.zeros(100), 8000)
    with pytest.raises(encoding.RenderError, match="ffmpeg failed"):
        encoding.mux_into_place(tmp_path / "missing.mp4", tmp_path / "sound.wav", out)
    assert out.read_bytes() == b"an older video"
    assert sorted(os.listdir(tmp_path)) == ["sound.wav", "video.mp4"]


def frames_file(path, n: int = 10) -> None:
    """A short H.264 file of `n` grey frames of SIZE, encoded by `FrameEncoder`."""
    encoder = encoding.FrameEncoder(path, SIZE, FPS)
    for k in range(n):
        encoder.add(np.full((SIZE[1], SIZE[0], 3), 20 * k, np.uint8))
    encoder.finish()
    with pytest.raises(RuntimeError, match="already encoded"):
        encoder.add(np.zeros((SIZE[1], SIZE[0], 3), np.uint8))
