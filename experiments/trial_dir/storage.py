"""Files of a trial directory, written atomically: a reader (or a run killed at any moment)
sees either the old file or the new one, never half of one. Files that belong together (a
report's page and figures, an evaluation's tables and eval.json) are written as one unit
(`write_files`). A write that fails raises `WriteError`, an OSError naming the file meant."""

from __future__ import annotations

import contextlib
import errno
import io
import json
import math
import os
import re
import zipfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd


class CorruptFileError(Exception):
    """A file of a trial directory cannot be read back (truncated, damaged)."""


# The temporary file `write_bytes` writes beside NAME: `.NAME.PID.tmp`, PID its writer's.
_TEMPORARY = re.compile(r"\.(?P<name>.+)\.(?P<pid>[0-9]+)\.tmp")


def temporary_writer(name: str) -> int | None:
    """The process id of the writer of a temporary file of `write_bytes` (or `check_writable`'s
    probe) named `name` (a file that a writer killed mid-write may leave behind); None if
    `name` is not such a file."""
    match = _TEMPORARY.fullmatch(name)
    return None if match is None else int(match["pid"])


class WriteError(OSError):
    """A file that could not be written (disk full, read-only place): `filename` is the file
    meant, not its temporary, and `strerror` the system's reason. Nothing of it was left."""


def reason(exc: OSError) -> str:
    """The system's reason for an OSError, for a message: "no space left on device"."""
    text = exc.strerror or str(exc)
    return text[:1].lower() + text[1:]


def _write_temporary(path: Path, data: bytes) -> Path:
    """`data` in a temporary file beside `path`, on disk (fsync); WriteError naming `path`."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)  # a failed write (disk full, killed) leaves no litter
        if isinstance(exc, OSError):
            raise WriteError(exc.errno, exc.strerror or str(exc), str(path)) from exc
        raise
    return tmp


def write_bytes(path: Path, data: bytes) -> None:
    """Write `data` to `path` atomically: through a temporary file beside it, then a rename."""
    path = Path(path)
    tmp = _write_temporary(path, data)
    try:
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise WriteError(exc.errno, exc.strerror or str(exc), str(path)) from exc


def keep_copy(path: Path, copy: Path) -> None:
    """`path`'s file also at `copy`, replacing it atomically, `path` untouched: a hard link
    where the filesystem has them (no bytes copied), else a copy through a temporary file."""
    tmp = copy.with_name(f".{copy.name}.{os.getpid()}.tmp")
    try:
        tmp.unlink(missing_ok=True)
        try:
            os.link(path, tmp)
        except OSError:  # a filesystem without hard links
            tmp = _write_temporary(copy, path.read_bytes())
        os.replace(tmp, copy)
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise WriteError(exc.errno, exc.strerror or str(exc), str(copy)) from exc


def write_files(directory: Path, files: dict[str, bytes]) -> list[Path]:
    """Files written into `directory` (created if missing) as one unit: each is first written
    to a temporary file beside it, and only when all are on disk are they renamed into place,
    in order. A write that fails (disk full, a read-only place, an interrupt) removes the
    temporaries and the folders this call created: nothing is changed. The last file vouches
    for the others (a page for its figures, eval.json for its tables): an older version of it
    is removed before any other file is replaced, so that it is never found beside a mix of
    old and new files. Returns the paths written, in order."""
    directory = Path(directory)
    created = [p for p in (directory, *directory.parents) if not p.exists()][::-1]
    written: list[tuple[Path, Path]] = []
    try:
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise WriteError(exc.errno, exc.strerror or str(exc), str(directory)) from exc
        for name, data in files.items():
            written.append((_write_temporary(directory / name, data), directory / name))
    except BaseException:
        for tmp, _ in written:
            with contextlib.suppress(OSError):
                tmp.unlink(missing_ok=True)
        for folder in reversed(created):
            with contextlib.suppress(OSError):
                folder.rmdir()
        raise
    replaced = 0
    try:
        if written:
            written[-1][1].unlink(missing_ok=True)
        for tmp, path in written:
            os.replace(tmp, path)
            replaced += 1
    except BaseException as exc:  # after the writes, a rename failing is all but unheard of
        for tmp, _ in written[replaced:]:
            with contextlib.suppress(OSError):
                tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            path = written[replaced][1]
            raise WriteError(exc.errno, exc.strerror or str(exc), str(path)) from exc
        raise
    return [path for _, path in written]


def check_writable(directory: Path) -> None:
    """Raise WriteError (naming `directory`) unless a file can be created in it, before work
    whose results would go there is done. A directory not made yet is checked where it would
    be made: in its nearest existing parent."""
    directory = Path(directory)
    while not directory.exists() and directory != directory.parent:
        directory = directory.parent
    if not directory.is_dir():
        raise WriteError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(directory))
    # Named as `write_bytes` names its temporaries: one a kill leaves is cleaned with theirs.
    probe = directory / f".write-test.{os.getpid()}.tmp"
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644))
        os.unlink(probe)
    except OSError as exc:
        raise WriteError(exc.errno, exc.strerror or str(exc), str(directory)) from exc


def json_bytes(obj: Any) -> bytes:
    """`obj` as the JSON text every file of the project holds (indented, keys sorted, standard
    JSON: a NaN or infinity is a ValueError)."""
    return (json.dumps(obj, indent=2, sort_keys=True, allow_nan=False) + "\n").encode()


def table_bytes(table: pd.DataFrame, plain: Sequence[str] = ()) -> bytes:
    """`table` as Parquet (without its index); the columns named in `plain` without a
    dictionary (values that hardly repeat, such as random goals, only grow by one)."""
    buffer = io.BytesIO()
    if plain:
        keep = [c for c in table.columns if c not in set(plain)]
        table.to_parquet(buffer, index=False, use_dictionary=keep)
    else:
        table.to_parquet(buffer, index=False)
    return buffer.getvalue()


def write_json(path: Path, obj: Any) -> None:
    """Standard JSON only: a NaN or infinity is a ValueError, never a non-standard `NaN` in a
    file other tools cannot read (a writer with such numbers says what they mean: see
    `finite_or_null`)."""
    write_bytes(path, json_bytes(obj))


def finite_or_null(obj: Any) -> Any:
    """`obj` with every float that is NaN or infinite replaced by None (JSON null), nested."""
    if isinstance(obj, dict):
        return {k: finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite_or_null(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def write_text(path: Path, text: str) -> None:
    write_bytes(path, text.encode("utf-8"))


def read_json(path: Path) -> Any:
    return json_from_bytes(Path(path).read_bytes(), path)


class DuplicateKeyError(ValueError):
    """A JSON object that names a key twice: which value was meant cannot be told."""


def _refuse_duplicates(pairs: list[tuple[str, Any]]) -> dict:
    found: dict[str, Any] = {}
    for key, value in pairs:
        if key in found:
            raise DuplicateKeyError(f"the key {key!r} appears twice in one object")
        found[key] = value
    return found


def strict_json(text: str) -> Any:
    """JSON text parsed as `json.loads` does, but a key given twice in one object is a
    DuplicateKeyError (json.loads keeps the last one silently): every JSON file the project
    reads is read so."""
    return json.loads(text, object_pairs_hook=_refuse_duplicates)


def json_from_bytes(data: bytes, path: Path) -> Any:
    """The JSON text `data`, read from the file at `path` (named in the error)."""
    try:
        return strict_json(data.decode())
    except (json.JSONDecodeError, UnicodeDecodeError, DuplicateKeyError) as exc:
        raise CorruptFileError(f"{path} is not valid JSON ({exc})") from None


def write_arrays(path: Path, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """NumPy arrays plus a JSON-able `meta` dict in one .npz file."""
    buffer = io.BytesIO()
    payload = {k: np.asarray(v) for k, v in arrays.items()}
    payload["__meta__"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    # mypy checks the ** values against savez's allow_pickle: bool too (none is named so).
    np.savez(buffer, **payload)  # type: ignore[arg-type]
    write_bytes(path, buffer.getvalue())


def read_meta(path: Path) -> dict:
    """The `meta` dict of a `write_arrays` file, without reading its arrays."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return json.loads(data["__meta__"].tobytes().decode())
    except (zipfile.BadZipFile, ValueError, KeyError, OSError, EOFError) as exc:
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None


def read_arrays(path: Path, data: bytes | None = None) -> tuple[dict[str, np.ndarray], dict]:
    """The arrays and `meta` of a `write_arrays` file; from `data`, its bytes already read (and
    checked), when given."""
    source = path if data is None else io.BytesIO(data)
    try:
        with np.load(source, allow_pickle=False) as loaded:
            arrays = {k: loaded[k] for k in loaded.files}
        meta = json.loads(arrays.pop("__meta__").tobytes().decode())
    except (zipfile.BadZipFile, ValueError, KeyError, OSError, EOFError) as exc:
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None
    return arrays, meta


def write_table(path: Path, table: pd.DataFrame, plain: Sequence[str] = ()) -> None:
    """`table` as Parquet at `path`, atomically (`table_bytes` says what `plain` is)."""
    write_bytes(path, table_bytes(table, plain))


def read_table(
    path: Path, columns: Sequence[str] | None = None, data: bytes | None = None
) -> pd.DataFrame:
    """A table written by `write_table`; with `columns`, only those of them it holds (a log
    written before a column existed lacks it), in that order: a reader that needs a few
    columns of a wide table decodes only them. From `data`, its bytes already read (and
    checked), when given."""
    try:
        source = _arrow_source(path, data)
        if columns is None:
            return pd.read_parquet(source())
        import pyarrow.parquet as pq

        held = set(pq.read_schema(source()).names)
        kept = [c for c in columns if c in held]
        return pd.read_parquet(source(), columns=kept)
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None


def _arrow_source(path: Path, data: bytes | None) -> Callable[[], Any]:
    """What opens the table for pyarrow, once per read: `path`, or a reader of `data` over a
    copy that Arrow owns. Given Python's bytes, pyarrow's
    reader keeps a reference to them that one of its pool threads may drop after the read
    returns; when that falls during interpreter exit, dropping it needs the GIL, the thread
    is ended inside a C++ destructor and the process aborts ("terminate called without an
    active exception", apache/arrow#49942), after a command has already printed its result.
    A buffer Arrow owns is freed without Python."""
    if data is None:
        return lambda: path
    import pyarrow as pa

    stream = pa.BufferOutputStream()
    stream.write(data)
    owned = stream.getvalue()
    return lambda: pa.BufferReader(owned)


def read_column(path: Path, name: str, data: bytes | None = None) -> list:
    """One column of a table written by `write_table`, as a list; every column is read and
    decoded (a check that the whole file is readable, at half the cost of `read_table`).
    CorruptFileError if the file cannot be read or lacks the column. From `data`, its bytes
    already read (and checked), when given."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(_arrow_source(path, data)())
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None
    if name not in table.column_names:
        raise CorruptFileError(f"{path} has no column {name!r}")
    return table.column(name).to_pylist()


def _alive(pid: int) -> bool:
    """Whether a process `pid` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's
        return True
    return True


def is_litter(name: str) -> bool:
    """Whether a file named `name` is a temporary file of a writer that no longer runs."""
    pid = temporary_writer(name)
    return pid is not None and not _alive(pid)


def remove_litter(trial_dir: str | os.PathLike) -> list[str]:
    """Remove the temporary files that writers killed mid-write (storage.write_bytes) left in a
    trial directory, wherever they lie in it (its memory/, log/, manifest/, an eval world's
    folder...); returns their paths relative to the directory.

    Called under the directory's lock: every writer of the trial's own files (run, eval, a
    batch task) holds it, so such a file there was left by a dead writer. A live process is
    still spared: a writer that takes no lock (a video rendered into the directory) may own
    it. A spared file is never taken for a result either (experiments/run/trial.py's derived
    files leave temporary files out)."""
    trial_dir = Path(trial_dir)
    removed = []
    for path in sorted(trial_dir.rglob(".*.tmp")):
        if is_litter(path.name):
            path.unlink(missing_ok=True)
            removed.append(path.relative_to(trial_dir).as_posix())
    return removed
