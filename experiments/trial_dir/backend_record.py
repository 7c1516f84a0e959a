"""What a trial records of its grasp backend (backend.json), and how a reader gets it back.

A grasp backend declares what a reader of its trials needs (sim/grasping/base.py: `reach`,
how far from the arm's base its hand can take the stick's handle; `capabilities`, whether its
objects are solid, are pushed, whether its movements have a closed form). A trial writes that
declaration (`make_record`) into its directory when it first computes (writing.py, as
records.py writes every record), and analysis and reports read it back (`read_record`), so
that none of them rebuilds a backend's rule or tests a backend's name: a backend added to the
registry is reported on its own terms without a line changed here.

Trials written before backend.json existed lack it. They ran one of the two backends of that
time, and `recorded_before` computes, from the trial's config.json, the record that backend
writes now, to the bit (tests/sim/test_backend_contract.py checks it against the backends
themselves): the one place that still knows those two by name, for old trials only.

`study_reach` is not a backend's declaration but the study's yardstick, the same for every
backend: the stick counts as "within reach" (experiments/analysis/curves.py) when its handle
lies within the arm's length plus the world's grasp distance, wherever each backend's own
hand can take it, so that two backends compare where the stick lay, not what each could take.

Reads and writes files and dicts only: no simulator (the layers in pyproject.toml).
"""

from __future__ import annotations

import functools
import os
import xml.etree.ElementTree as ET

from experiments.trial_dir import records
from experiments.trial_dir.config_file import with_added_settings
from experiments.trial_dir.layout import BACKEND_FILE
from models import playroom_xml

# What a record holds: the backend's name, its reach (m), then its capabilities.
CAPABILITIES = ("solid", "pushes", "closed_form")
FIELDS = ("grasp", "reach", *CAPABILITIES)


def make_record(grasp: str, reach: float, capabilities: dict[str, bool]) -> dict:
    """A record of FIELDS from a backend's name and declarations; ValueError if the
    capabilities are not exactly CAPABILITIES (a backend that declares another one needs a
    reader for it first)."""
    if tuple(capabilities) != CAPABILITIES:
        raise ValueError(f"a backend declares the capabilities {CAPABILITIES}, not {capabilities}")
    return {"grasp": grasp, "reach": float(reach), **{k: bool(v) for k, v in capabilities.items()}}


def read_record(trial_dir: str | os.PathLike, config: dict) -> dict:
    """A trial's record: its backend.json, checked against the trial's manifest
    (records.read_checked), or for a trial written before it, `recorded_before` of its
    config.json. ValueError (one line) for a record without FIELDS; storage.CorruptFileError
    for a backend.json that is not JSON or not what the trial recorded
    (manifest.DamagedFileError, saying how to regenerate it)."""
    record = records.read_checked(trial_dir, "backend")
    if record is None:
        record = recorded_before(config)
    if not isinstance(record, dict) or set(FIELDS) - set(record):
        raise ValueError(
            f"{records.record_path(trial_dir, 'backend')} lacks the backend's {', '.join(FIELDS)}"
        )
    return record


def recorded_before(config: dict) -> dict:
    """The record of a trial written before trials recorded their backend, from its config:
    what the two backends of that time declare, computed from the world settings it ran
    with. ValueError for any other backend (a trial of one lacks its backend.json)."""
    config = with_added_settings(config)
    grasp, world = config["trial"]["grasp"], config["world"]
    if grasp == "kinematic":  # the study's distance rules, movements in closed form
        capabilities = {"solid": False, "pushes": False, "closed_form": True}
        return make_record(grasp, study_reach(world), capabilities)
    if grasp == "physical":  # MuJoCo contacts: solid bodies, pushed unless switched off
        pushes = bool(world["push_objects"])
        capabilities = {"solid": True, "pushes": pushes, "closed_form": False}
        return make_record(grasp, _arm_length(world) + _contact_radii(), capabilities)
    raise ValueError(
        f"a {grasp!r} trial without its {BACKEND_FILE}: its backend's reach is unknown"
    )


def study_reach(world: dict) -> float:
    """The study's hand reach (module docstring), from a config's world section: the arm's
    length plus the grasp distance (m)."""
    return _arm_length(world) + world["grasp_distance"]


def _arm_length(world: dict) -> float:
    return float(sum(world["segment_lengths"]))


@functools.cache
def _contact_radii() -> float:
    """The radii of the hand sphere and of the stick's handle (models/playroom.xml), summed:
    how far beyond the arm's length the physical hand touches a handle."""
    geoms = {g.get("name"): g for g in ET.parse(playroom_xml()).iter("geom")}
    return sum(float(str(geoms[n].get("size")).split()[0]) for n in ("hand", "stick_handle"))
