"""The study's world numbers (docs/protocol.md §1, §5, §6), in one place, with their units.

Lengths are in the paper's units, which are metres in the MJCF model; the model is checked
against these numbers when it is loaded (sim/physics.py), so the two cannot disagree. The sizes
of the vectors the world exchanges with the learner (steps, samples, blocks) are the layout's
(models/layout.py), not settings of a world.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from models.checks import (
    INT64_MAX,
    check_choice,
    check_int,
    check_number,
    check_numbers,
    is_number,
    tuples,
)
from models.presets import PRESETS
from models.tracts import DEFAULT_TRACT, TRACTS

# The allowed values of the world's choices. sim/dmp.py and sim/experimenter.py, which apply
# them, import them from here, so that a config is checked without importing either.
DMP_KINDS = ("study", "project")  # sim/dmp.py
CATCH_RULES = ("study", "held_stick")  # sim/grasping/kinematic.py
ARM_DYNAMICS = ("set", "servo")  # sim/grasping/kinematic.py, sim/arm_servo.py
HELD_POSES = ("touch", "aligned")  # sim/grasping/physical.py
UNHELD_CONTACTS = ("solid", "sensed")  # sim/physics.py
CAREGIVER_CARRYING = ("welded", "placed")  # sim/grasping/carrying.py
STICK_RETURNS = ("never", "out_of_reach")  # sim/experimenter.py
N_RINGS = 3  # the study's rings; evaluations and reports name them ring1..ring3
# With push_objects off: the table damping of an unheld object (20 on x, y in the MJCF) times
# this. At 1e4 no random arm command of 600 moved an unheld object by 1 mm (MOVED_DISTANCE),
# against 112 pushes at 1 (seed 3, study preset); grasps and catches went on as before.
UNPUSHED_DAMPING_FACTOR = 1e4
# With settle_between_movements: physics steps (2 ms each) run between movements. Objects left
# overlapping parted within the next movement's first 5 control steps (50 physics steps) in 15
# of 16 cases seen (random commands, seed 3, study preset); twice that.
SETTLE_PHYSICS_STEPS = 100
# With unheld_contacts "sensed": every object geom's contact margin (m) and gap (m). MuJoCo finds
# a contact where the geoms' distance is below margin + gap and lets it act only below margin:
# -1 + 1 finds a contact where the geoms touch, as the solid room does (the grasp's contact
# sensors count it the same), and no touch ever acts (1 m of overlap never happens on this
# table).
SENSED_CONTACT_MARGIN = -1.0
SENSED_CONTACT_GAP = 1.0

# The key of a field's metadata that holds the value every trial written before the field
# existed ran with: a field added to a released config declares it beside itself, so that
# an older trial's config.json reads, resumes and keeps its identity as it was
# (experiments/config_file.py). Fields without it were in config.json before the first one
# added this way (the vocal tract, f838cfe).
BEFORE = "before"
# The key of a field's metadata that names the grasp backends (sim/grasping/registry.py) whose
# rules read the field; a field without it acts in every backend. Changing such a field for a
# trial of another backend would change nothing but its record, and is refused
# (`inert_settings`).
ACTS_ON = "acts_on"

# The room's scale, which bounds every length and position setting (m). The table of
# models/playroom.xml is 2.6 m square about the arm's base: a position on it lies within its
# half width, and no two points of it are farther apart than its diagonal, 3.68 m.
TABLE_HALF_WIDTH = 1.3
ROOM_SPAN = 3.7
# Above this scale, DMP weights in [-1, 1] are all or nothing. At the default 300, a weight of 1
# already carries a joint or an articulator 1.1 to 1.5 times to the bound its trajectory is
# clipped to (sim/dmp.py); at 100 times that, a weight of 0.01 does, and the clip flattens
# nearly every command.
DMP_WEIGHT_SCALE_MAX = 30000


@dataclass(frozen=True)
class WorldConfig:
    # Arm (docs/protocol.md §1).
    segment_lengths: tuple[float, float, float] = (0.25, 0.15, 0.10)  # m
    arm_rest_offset: float = math.pi / 2  # rad: at rest the arm points along +y
    # DMPs (docs/protocol.md §2): "study" (the study's own DMP) or "project" (pydmps style).
    dmp: str = "project"
    dmp_weight_scale: float = 300.0  # scales the weights in [-1, 1]
    # Objects (docs/protocol.md §1).
    stick_length: float = 0.25  # m
    stick_start_handle: tuple[float, float] = (-0.25, 0.0)  # m
    stick_start_angle: float = math.pi / 2  # rad: pointing along +y
    toy_replace_period: int = 20  # iterations between toy placements
    toy_rings: tuple[tuple[float, float], ...] = ((0.0, 0.5), (0.5, 0.75), (0.75, 1.0))  # m
    caregiver_box: float = 1.0  # caregiver uniform in [-box, box]^2, m
    # Kinematic grasp rules (docs/protocol.md §5).
    grasp_distance: float = 0.1  # m, hand to handle or toy
    catch_distance: float = dataclasses.field(default=0.1, metadata={ACTS_ON: ("kinematic",)})  # m
    # "study": the stick's tip catches a toy whether or not the stick is held (arm movements),
    # and the resting hand takes a stick lying within reach during vocal movements; "held_stick":
    # only a stick in the hand catches, and nothing is grasped during vocal movements.
    catch_rule: str = dataclasses.field(default="held_stick", metadata={ACTS_ON: ("kinematic",)})
    # Caregiver bringing a toy (docs/protocol.md §6): fraction of the remaining way per step.
    caregiver_bring_rate: float = 0.01
    # The experimenter returns a stick beyond the hand's reach to its start pose between
    # iterations ("out_of_reach"), or never, as in the study (sim/experimenter.py, §11).
    stick_return: str = "out_of_reach"
    # The physical backend's experimenter also returns a stick whose handle (the context's
    # stick position, the logs' `stick_distance`) lies farther than this from the arm's base (m):
    # where the learning arm's grasp rate falls below half its rate at the start pose, measured
    # on physical trials (docs/protocol.md D14). None: only when no contact can take it (no
    # point of the handle geom within the arm's length plus the hand's and the handle's radii,
    # 0.546 m), the rule of every trial written before this setting.
    stick_return_reach: float | None = dataclasses.field(
        default=0.53, metadata={BEFORE: None, ACTS_ON: ("physical",)}
    )
    # The vocal tract (sim/vocal/registry.py): "vtl", VocalTractLab, this project's; or "diva",
    # DIVA's formant map, the study's synthesizer, whose data the user installs (docs/protocol.md
    # D13). Trials written before the choice ran with VocalTractLab.
    voice: str = dataclasses.field(default=DEFAULT_TRACT, metadata={BEFORE: DEFAULT_TRACT})
    # Ablation of pushing (docs/comparison.md), never a default: False holds every
    # object that nothing holds where it lies (the physical backend multiplies its table
    # damping by UNPUSHED_DAMPING_FACTOR), so that, as in the kinematic rules, only a grasp, a
    # catch or the caregiver moves an object. The kinematic backend never pushes. Older trials
    # pushed.
    push_objects: bool = dataclasses.field(
        default=True, metadata={BEFORE: True, ACTS_ON: ("physical",)}
    )
    # Ablation of after-effects, never a default: True lets the physical room settle
    # between movements (SETTLE_PHYSICS_STEPS with the arm at rest), so that objects left
    # overlapping by a release, the arm's return to rest or the caregiver's putting a toy down
    # part before the next context is read, not during the next movement. Older trials did not
    # settle.
    settle_between_movements: bool = dataclasses.field(
        default=False, metadata={BEFORE: False, ACTS_ON: ("physical",)}
    )
    # A rung of the contact ladder, never a default: how the kinematic rules move
    # the arm. "set": its joints are set to the DMP targets (the study's rule); "servo": they
    # are where the physical model's position servos, tracking the same targets through the
    # dynamics with the arm touching nothing, take them (sim/arm_servo.py); the grasp, catch
    # and placement rules then act on that arm. Older trials set the arm.
    arm_dynamics: str = dataclasses.field(
        default="set", metadata={BEFORE: "set", ACTS_ON: ("kinematic",)}
    )
    # A rung of the contact ladder, never a default: where the physical backend
    # holds what it takes. "touch": welded at the pose of the touch (D16); "aligned": placed
    # and welded as the kinematic rules hold it, the stick's handle at the hand pointing along
    # the last segment, a toy at the hand or at the held stick's tip. Older trials: "touch".
    held_pose: str = dataclasses.field(
        default="touch", metadata={BEFORE: "touch", ACTS_ON: ("physical",)}
    )
    # A part of the contact step unbundled, never a default: what the physical
    # backend's objects do where something touches them. "solid": they push back (pushed, or
    # held still by the table with push_objects false: then they block the hand and what it
    # holds); "sensed": the touch is found, and the grasp's contact sensors read it as they
    # read any touch, but no contact between objects or with the hand exerts a force
    # (SENSED_CONTACT_MARGIN, SENSED_CONTACT_GAP): the contact's reach alone, nothing blocked
    # or pushed, as under the kinematic rules. Older trials: "solid".
    unheld_contacts: str = dataclasses.field(
        default="solid", metadata={BEFORE: "solid", ACTS_ON: ("physical",)}
    )
    # A part of the contact step unbundled, never a default: how the physical
    # backend's caregiver carries the toy she brings. "welded": her hand, a mocap body, welded
    # to the toy, which follows it through the dynamics (sim/grasping/carrying.py); "placed":
    # the toy itself put at each control step's point of her path, as the kinematic rules
    # place it. Either way it is lifted and touches nothing while carried. Older trials: welded.
    caregiver_carrying: str = dataclasses.field(
        default="welded", metadata={BEFORE: "welded", ACTS_ON: ("physical",)}
    )
    # A part of the contact step unbundled, never a default: True places the
    # kinematic backend's toys as the physical backend must place its solid ones, each clear
    # of the others and of the stick (sim/experimenter.py PLACEMENT_CLEARANCE); False places
    # them anywhere in their rings, as the study did. The physical backend always places clear.
    # Older trials: False.
    placements_clear: bool = dataclasses.field(
        default=False, metadata={BEFORE: False, ACTS_ON: ("kinematic",)}
    )

    def __post_init__(self) -> None:
        """Every field checked when the config is built (ValueError, one line): a typo or a
        number out of range is refused before a trial is written, never run as something else."""
        for name in ("segment_lengths", "stick_start_handle", "toy_rings"):
            object.__setattr__(self, name, tuples(getattr(self, name)))  # JSON gives lists
        w = "WorldConfig."
        lengths, positions = f"(0, {ROOM_SPAN}]", f"[-{TABLE_HALF_WIDTH}, {TABLE_HALF_WIDTH}]"
        check_numbers(w + "segment_lengths", self.segment_lengths, 3, lengths)
        check_number(w + "arm_rest_offset", self.arm_rest_offset)
        check_choice(w + "dmp", self.dmp, DMP_KINDS)
        check_number(w + "dmp_weight_scale", self.dmp_weight_scale, f"(0, {DMP_WEIGHT_SCALE_MAX}]")
        check_number(w + "stick_length", self.stick_length, lengths)
        check_numbers(w + "stick_start_handle", self.stick_start_handle, 2, positions)
        check_number(w + "stick_start_angle", self.stick_start_angle)
        # A period longer than any trial never places a toy: allowed, up to what an int64 holds.
        check_int(w + "toy_replace_period", self.toy_replace_period, 1, INT64_MAX)
        _check_rings(w + "toy_rings", self.toy_rings)
        # The caregiver stands on the table, within [-box, box]^2.
        check_number(w + "caregiver_box", self.caregiver_box, f"(0, {TABLE_HALF_WIDTH}]")
        for name in ("grasp_distance", "catch_distance"):
            check_number(w + name, getattr(self, name), lengths)
        check_choice(w + "catch_rule", self.catch_rule, CATCH_RULES)
        check_number(w + "caregiver_bring_rate", self.caregiver_bring_rate, "(0, 1]")
        check_choice(w + "stick_return", self.stick_return, STICK_RETURNS)
        if self.stick_return_reach is not None:
            check_number(w + "stick_return_reach", self.stick_return_reach, lengths)
        check_choice(w + "voice", self.voice, TRACTS)
        check_choice(w + "arm_dynamics", self.arm_dynamics, ARM_DYNAMICS)
        check_choice(w + "held_pose", self.held_pose, HELD_POSES)
        check_choice(w + "unheld_contacts", self.unheld_contacts, UNHELD_CONTACTS)
        check_choice(w + "caregiver_carrying", self.caregiver_carrying, CAREGIVER_CARRYING)
        for name in ("push_objects", "settle_between_movements", "placements_clear"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{w}{name} must be true or false, got {getattr(self, name)!r}")

    @property
    def arm_length(self) -> float:
        """Reach of the hand from the arm's base (m)."""
        return float(sum(self.segment_lengths))


def _check_rings(name: str, rings: Any) -> None:
    """N_RINGS (low, high) pairs of distances from the arm's base, 0 <= low < high <= ROOM_SPAN."""

    def ring_ok(ring: Any) -> bool:
        pair = isinstance(ring, tuple) and len(ring) == 2 and all(is_number(v) for v in ring)
        return pair and 0 <= ring[0] < ring[1] <= ROOM_SPAN

    if not (isinstance(rings, tuple) and len(rings) == N_RINGS and all(map(ring_ok, rings))):
        shown = repr(rings) if len(repr(rings)) <= 60 else repr(rings)[:57] + "..."
        raise ValueError(
            f"{name} must be {N_RINGS} [low, high] pairs of finite distances with "
            f"0 <= low < high <= {ROOM_SPAN}, got {shown}"
        )


def backend_switches() -> dict[str, tuple[str, ...]]:
    """Backend -> the world settings only some backends read that its rules read (each field's
    ACTS_ON), for every backend a field names."""
    switched = [f for f in dataclasses.fields(WorldConfig) if ACTS_ON in f.metadata]
    backends = sorted({g for f in switched for g in f.metadata[ACTS_ON]})
    return {g: tuple(f.name for f in switched if g in f.metadata[ACTS_ON]) for g in backends}


def inert_settings(grasp: str, changed: dict[str, Any]) -> list[str]:
    """The names among `changed` (world settings a trial changes from its preset) that no rule
    of the backend `grasp` reads: switches of other backends (`backend_switches`)."""
    switches = backend_switches()
    own = set(switches.get(grasp, ()))
    others = {name for names in switches.values() for name in names} - own
    return [name for name in changed if name in others]


# The fields' defaults: the base every preset edits, equal to the "project" preset's world. A
# room built without a config gets the default preset's (sim/playroom.py, models/presets.py).
DEFAULT_WORLD = WorldConfig()


def world_preset(preset: str, **overrides: Any) -> WorldConfig:
    """The world of a preset: "study" moves and grasps as the study's code did (its DMP; its
    catch rule, which only the kinematic backend applies: docs/protocol.md §11 D1, D10);
    "project" keeps this project's earlier choices. `overrides` change single fields."""
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}: one of {PRESETS}")
    study = {"dmp": "study", "catch_rule": "study"}
    return dataclasses.replace(
        DEFAULT_WORLD, **{**(study if preset == "study" else {}), **overrides}
    )


if TYPE_CHECKING:  # typeshed's protocol of dataclasses, for the type checker only
    from _typeshed import DataclassInstance

Config = TypeVar("Config", bound="DataclassInstance")


def config_from_dict(cls: type[Config], values: dict[str, Any]) -> Config:
    """A frozen config dataclass from its `dataclasses.asdict` form read back from JSON (lists
    become tuples again); ValueError naming unknown fields."""
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ValueError(f"unknown {cls.__name__} fields: {', '.join(unknown)}")
    return cls(**{k: tuples(v) for k, v in values.items()})
