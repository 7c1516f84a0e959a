"""A file damaged as a disk fault damages it, one bit, and still readable: a JSON file that
still parses, with another number or checksum in it."""

from __future__ import annotations

import json
from pathlib import Path


def flip_bit(path: Path, text: str) -> None:
    """The lowest bit of the last character of the first `text` in the file at `path` flipped:
    a digit stays a digit (0 and 1, 2 and 3, ...), so a number in JSON stays a number."""
    data = bytearray(path.read_bytes())
    at = data.index(text.encode()) + len(text) - 1
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


def flip_number(path: Path, key: str, value: float) -> None:
    """The number `value` of the first entry `key` in the JSON file at `path` changed by one
    bit, in its first digit after the point (its last digit if it has none): still JSON, and
    another number than `value` once read."""
    text = json.dumps(value)
    kept = text[: text.index(".") + 2] if "." in text else text
    flip_bit(path, f'"{key}": {kept}')
