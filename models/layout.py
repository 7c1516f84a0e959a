"""The study's sensorimotor layout: the vectors the world and the learner exchange.

`sim` fills these vectors and `learner` reads them, so both import this module and nothing
else states a size, an order or a sample step. It depends on nothing (not even NumPy): the
learner can use it without MuJoCo. Numbers: docs/protocol.md §2-§4 and §8.
"""

from __future__ import annotations

from dataclasses import dataclass

# Movements (docs/protocol.md §2): a DMP gives 50 targets, one per control step.
N_STEPS = 50
N_JOINTS = 3
ARM_BASIS_FUNCTIONS = 6  # DMP weights per joint; plus one end position
N_ARTICULATORS = 7
VOICE_BASIS_FUNCTIONS = 2  # DMP weights per articulator; plus a start and an end
ARM_DIM = N_JOINTS * (ARM_BASIS_FUNCTIONS + 1)  # 21
VOICE_DIM = N_ARTICULATORS * (VOICE_BASIS_FUNCTIONS + 2)  # 28
MOTOR_DIMS: dict[str, int] = {"arm": ARM_DIM, "voice": VOICE_DIM}
MOTOR_SPACES: tuple[str, ...] = tuple(MOTOR_DIMS)

# Sensory feedback (docs/protocol.md §4): each block is 5 samples of x then 5 of y (for the
# sound, of F1 then F2), taken after these control steps (1-based).
SAMPLE_STEPS: tuple[int, ...] = (1, 13, 25, 38, 50)
SAMPLE_INDICES: tuple[int, ...] = tuple(step - 1 for step in SAMPLE_STEPS)  # into 50 steps
N_SAMPLES = len(SAMPLE_STEPS)
BLOCK_DIM = 2 * N_SAMPLES  # 10
TOYS: tuple[str, ...] = ("toy1", "toy2", "toy3")
TRACKED_OBJECTS: tuple[str, ...] = ("hand", "stick", *TOYS)  # the blocks that are positions
SENSORY_BLOCKS: tuple[str, ...] = (*TRACKED_OBJECTS, "sound")
SENSORY_DIM = BLOCK_DIM * len(SENSORY_BLOCKS)  # 60

# An object's block "changed" once a sample lies farther than this from where the object
# started (m; for the sound, normalised log2 Hz): the learner's storing rule and the world's
# "moved" events share it. Resting objects in contact jitter by far less; movements are cm.
MOVED_DISTANCE = 1e-3

# Context (docs/protocol.md §4): positions before the movement, x then y of each slot.
CONTEXT_SLOTS: tuple[str, ...] = ("stick", *TOYS, "caregiver")
CONTEXT_DIM = 2 * len(CONTEXT_SLOTS)  # 10


def block_slice(block: str) -> slice:
    """Where the named sensory block lies in the feedback s (60,)."""
    if block not in SENSORY_BLOCKS:
        raise ValueError(f"unknown sensory block {block!r}: one of {SENSORY_BLOCKS}")
    k = SENSORY_BLOCKS.index(block)
    return slice(k * BLOCK_DIM, (k + 1) * BLOCK_DIM)


def context_indices(slot: str) -> tuple[int, int]:
    """Where the named slot's x, y lie in the context c (10,)."""
    if slot not in CONTEXT_SLOTS:
        raise ValueError(f"unknown context slot {slot!r}: one of {CONTEXT_SLOTS}")
    k = CONTEXT_SLOTS.index(slot)
    return 2 * k, 2 * k + 1


@dataclass(frozen=True)
class ModelSpec:
    """One sensorimotor model, an arrow of the paper's Fig. 2: motor space -> sensory block,
    given context slots."""

    number: int  # 1..10, as in docs/protocol.md §8
    motor_space: str  # one of MOTOR_SPACES
    sensory_block: str  # one of SENSORY_BLOCKS
    context_slots: tuple[str, ...]  # of CONTEXT_SLOTS, in this order in the model's context
    imitates_caregiver: bool = False  # draws some goals from heard caregiver sounds

    def __post_init__(self) -> None:
        if self.motor_space not in MOTOR_SPACES:
            raise ValueError(f"model {self.number}: unknown motor space {self.motor_space!r}")
        block_slice(self.sensory_block)
        for slot in self.context_slots:
            context_indices(slot)

    @property
    def name(self) -> str:
        context = ", ".join(self.context_slots) or "none"
        return f"{self.motor_space} -> {self.sensory_block} | {context}"

    @property
    def context_dims(self) -> tuple[int, ...]:
        """Indices into the context c (10,) of this model's context."""
        return tuple(i for slot in self.context_slots for i in context_indices(slot))

    @property
    def sensory_slice(self) -> slice:
        """Where this model's sensory block lies in the feedback s (60,)."""
        return block_slice(self.sensory_block)


# The 10 models of the study (docs/protocol.md §8).
MODELS: tuple[ModelSpec, ...] = (
    ModelSpec(1, "arm", "hand", ()),
    ModelSpec(2, "arm", "stick", ("stick",)),
    ModelSpec(3, "arm", "toy1", ("stick", "toy1")),
    ModelSpec(4, "arm", "toy2", ("stick", "toy2")),
    ModelSpec(5, "arm", "toy3", ("stick", "toy3")),
    ModelSpec(6, "arm", "sound", ("stick", *TOYS)),
    ModelSpec(7, "voice", "toy1", ("toy1", "caregiver")),
    ModelSpec(8, "voice", "toy2", ("toy2", "caregiver")),
    ModelSpec(9, "voice", "toy3", ("toy3", "caregiver")),
    ModelSpec(10, "voice", "sound", (), imitates_caregiver=True),
)
