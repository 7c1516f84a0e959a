"""Files of a trial directory, written atomically: a reader (or a run killed at any moment)
sees either the old file or the new one, never half of one."""

from __future__ import annotations

import io
import json
import math
import os
import re
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd


class CorruptFileError(Exception):
    """A file of a trial directory cannot be read back (truncated, damaged)."""


# The temporary file `write_bytes` writes beside NAME: `.NAME.PID.tmp`, PID its writer's.
_TEMPORARY = re.compile(r"\.(?P<name>.+)\.(?P<pid>[0-9]+)\.tmp")


def temporary_writer(name: str) -> int | None:
    """The process id of the writer of a temporary file of `write_bytes` named `name` (a file
    that a writer killed mid-write may leave behind); None if `name` is not such a file."""
    match = _TEMPORARY.fullmatch(name)
    return None if match is None else int(match["pid"])


def write_bytes(path: Path, data: bytes) -> None:
    """Write `data` to `path` atomically: through a temporary file beside it, then a rename."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)  # a failed write (disk full, killed) leaves no litter
        raise


def write_json(path: Path, obj: Any) -> None:
    """Standard JSON only: a NaN or infinity is a ValueError, never a non-standard `NaN` in a
    file other tools cannot read (a writer with such numbers says what they mean: see
    `finite_or_null`)."""
    text = json.dumps(obj, indent=2, sort_keys=True, allow_nan=False)
    write_bytes(path, (text + "\n").encode())


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
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise CorruptFileError(f"{path} is not valid JSON ({exc})") from None


def write_arrays(path: Path, arrays: dict[str, np.ndarray], meta: dict) -> None:
    """NumPy arrays plus a JSON-able `meta` dict in one .npz file."""
    buffer = io.BytesIO()
    payload = {k: np.asarray(v) for k, v in arrays.items()}
    payload["__meta__"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(buffer, **payload)
    write_bytes(path, buffer.getvalue())


def read_arrays(path: Path) -> tuple[dict[str, np.ndarray], dict]:
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        meta = json.loads(arrays.pop("__meta__").tobytes().decode())
    except (zipfile.BadZipFile, ValueError, KeyError, OSError, EOFError) as exc:
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None
    return arrays, meta


def write_table(path: Path, table: pd.DataFrame) -> None:
    buffer = io.BytesIO()
    table.to_parquet(buffer, index=False)
    write_bytes(path, buffer.getvalue())


def read_table(path: Path) -> pd.DataFrame:
    try:
        return pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None


def read_column(path: Path, name: str) -> list:
    """One column of a table written by `write_table`, as a list; every column is read and
    decoded (a check that the whole file is readable, at half the cost of `read_table`).
    CorruptFileError if the file cannot be read or lacks the column."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path)
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise CorruptFileError(f"{path} is damaged or truncated ({exc})") from None
    if name not in table.column_names:
        raise CorruptFileError(f"{path} has no column {name!r}")
    return table.column(name).to_pylist()


def config_differences(a: dict, b: dict, prefix: str = "") -> list[tuple[str, Any, Any]]:
    """(dotted key, value in a, value in b) of every setting where two nested configs differ."""
    out = []
    for k in sorted(set(a) | set(b)):
        va, vb = a.get(k), b.get(k)
        if isinstance(va, dict) and isinstance(vb, dict):
            out += config_differences(va, vb, f"{prefix}{k}.")
        elif va != vb:
            out.append((f"{prefix}{k}", va, vb))
    return out
