"""One writer per trial directory: an OS file lock held for the life of the writer.

The lock is `flock` on a file in the directory, so the kernel releases it whenever the holding
process ends, `kill -9` and a lost Dask worker included: a stale lock cannot outlive its
holder. The holder writes its process id and host into the file so that a refused writer can
name it: on a cluster the holder is often on another machine, where its pid means nothing.
Within one process the lock is re-entrant (a batch task runs a trial, then evaluates it).
"""

from __future__ import annotations

import fcntl
import os
import socket
import time
from pathlib import Path

from experiments.trial_dir.layout import LOCK_FILE

# How often a waiting writer tries again (s).
POLL_S = 0.5
# How much of the lock file a refused writer reads: a pid and a host name (at most 255 bytes).
HOLDER_BYTES = 300


def _holder_text(holder: str) -> str:
    """The holder as the lock file names it, "pid P on HOST" (a lock written before hosts were
    recorded names only its pid)."""
    pid, _, host = holder.partition(" ")
    if not pid:
        return "pid unknown"
    return f"pid {pid} on {host}" if host else f"pid {pid}"


def holds_only_lock(directory: Path) -> bool:
    """Whether a directory holds nothing but a writer's lock (a run killed before it wrote
    anything leaves that): a directory to use again, not something else's."""
    return all(p.name == LOCK_FILE for p in directory.iterdir())


class DirectoryLocked(Exception):
    """Another process writes into the directory; the message names it and its process id."""


class DirectoryLock:
    """The exclusive right to write into `directory` (created if missing)."""

    _held: dict[Path, tuple[DirectoryLock, int]] = {}  # this process's locks, with depth

    def __init__(self, directory: str | os.PathLike) -> None:
        self.directory = Path(directory).resolve()
        self.path = self.directory / LOCK_FILE
        self._fd: int | None = None

    @classmethod
    def acquired(cls, directory: str | os.PathLike) -> DirectoryLock:
        """The lock of `directory`, taken now (`acquire`, without waiting)."""
        return cls(directory).acquire()

    def acquire(self, wait_s: float = 0.0) -> DirectoryLock:
        """Take the lock, waiting up to `wait_s` seconds for its holder to finish;
        DirectoryLocked if it is still held then."""
        held = DirectoryLock._held.get(self.directory)
        if held is not None:
            owner, depth = held
            DirectoryLock._held[self.directory] = (owner, depth + 1)
            self._fd = owner._fd
            return self
        self.directory.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        deadline = time.monotonic() + wait_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    holder = os.pread(fd, HOLDER_BYTES, 0).decode(errors="replace").strip()
                    os.close(fd)
                    raise DirectoryLocked(
                        f"{self.directory} is being written by another process "
                        f"({_holder_text(holder)}); wait for it to finish or stop it"
                    ) from None
                time.sleep(POLL_S)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()} {socket.gethostname()}\n".encode(), 0)
        self._fd = fd
        DirectoryLock._held[self.directory] = (self, 1)
        return self

    def release(self) -> None:
        """Give the lock up (the outermost release of this process frees it)."""
        held = DirectoryLock._held.get(self.directory)
        if held is None or self._fd is None:
            return
        owner, depth = held
        fd, self._fd = self._fd, None  # every lock of one directory shares the owner's fd
        if depth > 1:
            DirectoryLock._held[self.directory] = (owner, depth - 1)
            return
        del DirectoryLock._held[self.directory]
        owner._fd = None
        # The pid is left in the file: harmless, since only the flock counts.
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)

    def __enter__(self) -> DirectoryLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
