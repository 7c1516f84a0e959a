"""The study's vocal numbers (docs/protocol.md §4, §6, §7), in one place."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from models.checks import check_int, check_number, is_number, tuples
from models.layout import TOYS

WORD_LENGTH = 3  # vowels per word: v1, v2, v3 (its trajectory passes their midpoints)


@dataclass(frozen=True)
class VoiceConfig:
    # Vowels and words of the public implementation (docs/protocol.md §6).
    vowels: tuple[str, ...] = ("o", "u", "i", "e", "y")
    words: tuple[str, ...] = ("oey", "uye", "iuo", "eyu", "eou", "yeo")
    # The study's target formants (F1, F2) in Hz. Our targets are the VocalTractLab speaker's
    # own vowels (see `sim.vocal.vtl.words`); these are kept for comparison in docs/voice.md.
    # Rows (vowel, F1, F2); a tuple so that the config stays hashable.
    study_vowel_hz: tuple[tuple[str, float, float], ...] = (
        ("o", 500.0, 900.0),
        ("y", 300.0, 1700.0),
        ("u", 300.0, 800.0),
        ("e", 400.0, 2200.0),
        ("i", 300.0, 2300.0),
    )
    # Sound features: log2 F1 at the 5 sample points minus f1_offset, then log2 F2 minus
    # f2_offset (docs/protocol.md §4), in log2(Hz).
    f1_offset: float = 8.5
    f2_offset: float = 10.25
    # The caregiver recognises a sound within this Euclidean distance of a word (10D space).
    recognition_distance: float = 0.4
    n_names: int = 3  # words that become toy names; the other 3 are distractors

    def __post_init__(self) -> None:
        """Every field checked when the config is built (ValueError, one line)."""
        for name in ("vowels", "words", "study_vowel_hz"):
            object.__setattr__(self, name, tuples(getattr(self, name)))  # JSON gives lists
        v = "VoiceConfig."
        if not _distinct_strings(self.vowels) or any(len(x) != 1 for x in self.vowels):
            raise ValueError(f"{v}vowels must be distinct single letters, got {self.vowels!r}")
        words_ok = _distinct_strings(self.words) and all(
            len(w) == WORD_LENGTH and set(w) <= set(self.vowels) for w in self.words
        )
        if not words_ok:
            raise ValueError(
                f"{v}words must be distinct words of {WORD_LENGTH} of the vowels "
                f"{''.join(self.vowels)}, got {self.words!r}"
            )
        if not (isinstance(self.study_vowel_hz, tuple) and all(map(_hz_row, self.study_vowel_hz))):
            raise ValueError(
                f"{v}study_vowel_hz must be (vowel, F1 Hz > 0, F2 Hz > 0) rows, "
                f"got {self.study_vowel_hz!r}"
            )
        check_number(v + "f1_offset", self.f1_offset)
        check_number(v + "f2_offset", self.f2_offset)
        check_number(v + "recognition_distance", self.recognition_distance, "(0, inf)")
        # names[i] names toy i + 1 (sim/caregiver.py), and the rest must leave a distractor.
        check_int(v + "n_names", self.n_names, minimum=1)
        if self.n_names != len(TOYS) or self.n_names >= len(self.words):
            raise ValueError(
                f"{v}n_names must be {len(TOYS)} (one name per toy) and fewer than the "
                f"{len(self.words)} words, got {self.n_names!r}"
            )

    @property
    def n_points(self) -> int:
        """Points of a word's trajectory: v1, mid(v1, v2), v2, mid(v2, v3), v3."""
        return 5

    def study_hz(self, vowel: str) -> tuple[float, float]:
        """The study's (F1, F2) in Hz for one vowel."""
        for name, f1, f2 in self.study_vowel_hz:
            if name == vowel:
                return f1, f2
        raise ValueError(f"unknown vowel {vowel!r}; expected one of {self.vowels}")


def _distinct_strings(values: Any) -> bool:
    ok = isinstance(values, tuple) and len(values) > 0
    return ok and all(isinstance(x, str) for x in values) and len(set(values)) == len(values)


def _hz_row(row: Any) -> bool:
    if not (isinstance(row, tuple) and len(row) == 3 and isinstance(row[0], str)):
        return False
    return all(is_number(hz) and hz > 0 for hz in row[1:])


DEFAULT_VOICE = VoiceConfig()
