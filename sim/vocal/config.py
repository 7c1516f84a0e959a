"""The study's vocal numbers (docs/protocol.md §4, §6, §7), in one place."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class VoiceConfig:
    # Vowels and words of the public implementation (docs/protocol.md §6).
    vowels: tuple[str, ...] = ("o", "u", "i", "e", "y")
    words: tuple[str, ...] = ("oey", "uye", "iuo", "eyu", "eou", "yeo")
    # The study's target formants (F1, F2) in Hz. Our targets are the VocalTractLab speaker's
    # own vowels (see `sim.vocal.words`); these are kept for comparison in the README.
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


DEFAULT_VOICE = VoiceConfig()
