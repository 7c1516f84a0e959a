"""What a rung of the contact ladder changes from the rung before, all of it: the rungs table of
the ladder's page (experiments/report/ladder_page.py) reads it.

A step between rungs of one backend changes what their configs say. A step from one backend to
the other changes more than its configs say, and the page must not hide any of it:
- every setting whose value differs, each said with which rung reads it (a setting only one
  backend reads, experiments/trial_dir/eval_worlds.py READ_BY: "not read by the earlier rung's
  kinematic backend" where the earlier rung had no such rule at all, rather than a change it made);
- every setting only one of the two backends reads, even where its value did not change (a
  rule one rung applies and the other does not: the kinematic catch distance, the physical
  stick-return reach);
- what each rung's world does as its trials recorded it (backend.json, experiments/
  backend_record.py): how far the hand can take the stick, whether objects are solid (then
  placements keep clear of the stick and of each other, and unheld objects block what
  touches them), whether they are pushed, whether movements are computed in closed form.
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from experiments.report.ablations import describe_change
from experiments.trial_dir.eval_worlds import READ_BY, SWITCHES

# What each recorded capability means on the page (backend.json's fields, CAPABILITIES).
CAPABILITY_TEXT = {
    "solid": "solid objects (placements clear of the stick and of each other; unheld objects "
    "block the hand and what it holds)",
    "pushes": "objects pushed by what touches them",
    "closed_form": "movements computed in closed form (no dynamics)",
}
REACH_TEXT = "the hand takes the stick's handle within (m)"


@dataclass(frozen=True)
class RungWorld:
    """One rung's world: its group config (config.json's, seed removed) and what its trials'
    backend recorded (capability -> value, `reach` in m; a field no trial recorded absent)."""

    config: dict
    backend: dict

    @property
    def grasp(self) -> str:
        return str(self.config["trial"]["grasp"])

    def reads(self, setting: str) -> bool:
        """Whether this rung's backend reads world setting `setting` (one it is not a switch
        of some backend is read by every backend)."""
        return setting not in SWITCHES or setting in READ_BY.get(self.grasp, ())


def recorded_backend(trials: pd.DataFrame) -> dict:
    """The backend record a rung's trials agree on (reach and capabilities: columns of
    `BatchResults.trials`); a field they do not all hold one value of is left out."""
    out = {}
    for field in ("reach", *CAPABILITY_TEXT):
        if field in trials and trials[field].notna().all() and trials[field].nunique() == 1:
            out[field] = trials[field].iloc[0]
    return out


def _reader_note(setting: str, before: RungWorld, after: RungWorld) -> str:
    earlier, later = before.reads(setting), after.reads(setting)
    if earlier and later:
        return ""
    if not earlier and not later:
        return " (read by neither rung's backend)"
    if later:
        return f" (not read by the earlier rung's {before.grasp} backend)"
    return f" (not read by the later rung's {after.grasp} backend)"


def _yes(value: object) -> str:
    return "yes" if value else "no"


def describe(before: RungWorld, after: RungWorld) -> str:
    """Everything the later rung changes (module docstring), "; "-separated."""
    parts = []
    for part in describe_change(before.config, after.config).split("; "):
        key = part.split(":", 1)[0]
        note = (
            _reader_note(key.removeprefix("world."), before, after)
            if key.startswith("world.")
            else ""
        )
        parts.append(part + note)
    if before.grasp != after.grasp:
        for setting in SWITCHES:
            if before.reads(setting) == after.reads(setting):
                continue
            value = before.config["world"].get(setting), after.config["world"].get(setting)
            if value[0] != value[1]:
                continue  # listed above
            which = ("earlier", before) if before.reads(setting) else ("later", after)
            parts.append(
                f"world.{setting}: {value[0]}, read by the {which[0]} rung's {which[1].grasp} "
                "backend only"
            )
        for field in ("reach", *CAPABILITY_TEXT):
            if field not in before.backend or field not in after.backend:
                parts.append(f"backend: {field} not recorded by both rungs' trials")
                continue
            a, b = before.backend[field], after.backend[field]
            if field == "reach":
                if a != b:
                    parts.append(f"backend: {REACH_TEXT} {a:.3f} -> {b:.3f}")
            elif a != b:
                parts.append(f"backend: {CAPABILITY_TEXT[field]}: {_yes(a)} -> {_yes(b)}")
    return "; ".join(p for p in parts if p != "the baseline's settings") or "nothing"
