"""Encoding a video: frames to H.264 with mediapy, the sound track muxed in with ffmpeg, and the
finished MP4 moved into place atomically.

Both steps use the ffmpeg binary that imageio-ffmpeg ships, so nothing has to be installed by
hand. This module imports no mujoco: encoding needs no OpenGL.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import tempfile
from pathlib import Path

import imageio_ffmpeg
import mediapy
import numpy as np

from experiments.trial_dir import storage

# Quality of the H.264 stream (constant rate factor: lower is better and larger).
VIDEO_CRF = 20


class RenderError(RuntimeError):
    """The machine cannot render or encode: no offscreen GL context, or ffmpeg failed."""


def ffmpeg_exe() -> str:
    """The ffmpeg binary shipped by imageio-ffmpeg (nothing to install by hand)."""
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as exc:
        raise RenderError(f"imageio-ffmpeg has no ffmpeg binary: {exc}") from exc


class FrameEncoder:
    """Frames streamed into the H.264 file `path` as they come, so memory holds none of them.

    size: (width, height) px; fps: frames per second of the stream. The encoder starts at the
    first frame; `finish` ends the stream, after which no frame may be added (a new encoder
    would overwrite the file). `close` stops it without reporting errors, for clean-up.
    """

    def __init__(self, path: Path, size: tuple[int, int], fps: float, crf: int = VIDEO_CRF) -> None:
        self.path, self.size, self.fps, self.crf = Path(path), size, fps, crf
        self.n_frames = 0
        self.finished = False
        self._writer: mediapy.VideoWriter | None = None

    def add(self, image: np.ndarray) -> None:
        """Encode one (height, width, 3) uint8 frame."""
        if self.finished:
            raise RuntimeError(f"the frames of {self.path} were already encoded")
        if self._writer is None:
            mediapy.set_ffmpeg(ffmpeg_exe())
            width, height = self.size
            self._writer = mediapy.VideoWriter(
                self.path, (height, width), fps=self.fps, crf=self.crf
            )
            try:
                self._writer.__enter__()
            except Exception as exc:
                # Left unset, so that the next frame tries again.
                self._writer = None
                raise RenderError(f"ffmpeg could not start encoding frames: {exc}") from exc
        self._writer.add_image(image)
        self.n_frames += 1

    def finish(self) -> None:
        """End the stream (idempotent); RenderError if ffmpeg failed to encode it."""
        self.finished = True
        if self._writer is not None:
            try:
                self._writer.close()
            except Exception as exc:
                raise RenderError(f"ffmpeg failed to encode the frames: {exc}") from exc
            finally:
                self._writer = None

    def close(self) -> None:
        """Stop the encoder, errors ignored: for clean-up after a failure or when done."""
        if self._writer is not None:
            with contextlib.suppress(Exception):
                self._writer.close()
            self._writer = None


def mux(video_path: Path, wav_path: Path, out_path: Path) -> None:
    """Copy the video stream and encode the WAV as AAC into the MP4 `out_path`."""
    argv = [
        ffmpeg_exe(),
        "-y",
        "-loglevel",
        "error",
        "-i",
        os.fspath(video_path),
        "-i",
        os.fspath(wav_path),
        "-map",
        "0:v:0",
        "-map",
        "1:a:0",
        "-c:v",
        "copy",
        "-c:a",
        "aac",
        # The caller makes the track a little longer than the video, so the video's end decides.
        "-shortest",
        "-movflags",
        "+faststart",
        "-f",
        "mp4",
        os.fspath(out_path),
    ]
    result = subprocess.run(argv, capture_output=True, text=True)
    if result.returncode != 0:
        detail = result.stderr.strip().splitlines()[-1:] or ["no message"]
        raise RenderError(f"ffmpeg failed to mux the sound (exit {result.returncode}): {detail[0]}")


def mux_into_place(video_path: Path, wav_path: Path, out_path: Path) -> Path:
    """Mux video and sound (see `mux`) into `out_path`, which appears whole or not at all.

    ffmpeg writes beside `video_path` (a scratch folder); the finished file then goes into
    place through `storage.write_bytes`, the project's one atomic writer (a temporary file
    beside the target, fsync, rename). Returns `out_path`.
    """
    fd, name = tempfile.mkstemp(prefix="muxed-", suffix=".mp4", dir=Path(video_path).parent)
    os.close(fd)
    muxed = Path(name)
    try:
        mux(video_path, wav_path, muxed)
        storage.write_bytes(Path(out_path), muxed.read_bytes())
    finally:
        with contextlib.suppress(FileNotFoundError):
            muxed.unlink()
    return Path(out_path)
