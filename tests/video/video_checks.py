"""What the video tests share: a film's size and timing, a test tone, and reading back what an
MP4 holds (frames, sound, streams) with imageio-ffmpeg's ffmpeg."""

from __future__ import annotations

import subprocess

import imageio_ffmpeg
import numpy as np
from scipy.io import wavfile

SIZE = (160, 120)
FPS = 50.0
LEAD, HOLD = 2, 3
STEPS = 50
TONE_HZ = 440.0
TONE_RATE = 22_050
TONE_S = 0.4


def tone(seconds: float = TONE_S) -> tuple[np.ndarray, int]:
    t = np.arange(int(seconds * TONE_RATE)) / TONE_RATE
    return 0.5 * np.sin(2 * np.pi * TONE_HZ * t), TONE_RATE


def decoded_frames(path) -> np.ndarray:
    """(n, h, w, 3) uint8: every frame of the MP4 (mediapy 1.2.7 cannot read with ffmpeg 9:
    it passes -vsync, which ffmpeg 9 removed)."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    return np.stack([np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader])


def decoded_sound(path, tmp_path) -> tuple[np.ndarray, int]:
    """The MP4's audio stream decoded to (n,) int16 samples and its rate; fails if absent."""
    wav = tmp_path / "decoded.wav"
    ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()
    result = subprocess.run(
        [ffmpeg, "-v", "error", "-y", "-i", str(path), "-map", "0:a:0", str(wav)],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    rate, samples = wavfile.read(wav)
    return samples, rate


def stream_listing(path) -> str:
    """What `ffmpeg -i FILE` says about the file's streams (it exits 1: no output given)."""
    ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()
    return subprocess.run([ffmpeg, "-i", str(path)], capture_output=True, text=True).stderr
