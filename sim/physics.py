"""The playroom's MuJoCo physics, with measurements named for what they measure."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from models import playroom_xml
from models.layout import TOYS
from sim.config import (
    DEFAULT_WORLD,
    SENSED_CONTACT_GAP,
    SENSED_CONTACT_MARGIN,
    UNPUSHED_DAMPING_FACTOR,
    WorldConfig,
)
from sim.dm_control_import import dm_mujoco
from sim.mujoco_import import mujoco

if TYPE_CHECKING:
    from sim.movement import MovementTrace

ARM_JOINTS = ("shoulder", "elbow", "wrist")
OBJECTS = ("stick", *TOYS)  # the bodies that move in the plane with joints x, y, yaw
# Physics steps per control step: the model's 2 ms timestep makes a 20 ms control step, so a
# 50-step movement lasts 1 s.
CONTROL_SUBSTEPS = 10
# The contact sensors of models/playroom.xml the physical grasp acts on, in this order: the
# hand on the stick's handle, the hand on each toy, the stick's tip on each toy.
GRASP_CONTACTS = (
    "hand_stick",
    *(f"hand_{toy}" for toy in TOYS),
    *(f"stick_{toy}" for toy in TOYS),
)
# The caregiver's path when she brings nothing (PlayroomPhysics.control_steps).
_NOT_BROUGHT = np.empty((0, 2))
# A movement not traced: the compiled steps' trace arguments with no rows.
_NOT_TRACED_QPOS = np.empty((0, 0))
_NOT_TRACED_MOCAP = np.empty((0, 0))
INTEGRATION_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


class PlayroomPhysics(dm_mujoco.Physics):
    """Physics of the playroom. Positions are (x, y) in the table plane, in metres.

    Index lookups are cached once: the named accessors of dm_control cost microseconds per
    call, and these measurements run every control step.
    """

    config: WorldConfig = DEFAULT_WORLD

    @classmethod
    def load(
        cls, config: WorldConfig = DEFAULT_WORLD, path: str | os.PathLike | None = None
    ) -> PlayroomPhysics:
        """Compile the playroom MJCF file (the packaged models/playroom.xml by default) for the
        world `config`; ValueError naming every length on which the two disagree."""
        physics = cls.from_xml_path(str(path or playroom_xml()))
        physics.config = config
        if not config.push_objects:
            # The ablation of pushing (WorldConfig.push_objects): the table holds an object
            # that nothing holds. Lifting (held, carried) still clears the damping entirely
            # (sim/model_edits.py), and the integrator treats damping implicitly, so this
            # stays stable however large.
            physics.model.ptr.dof_damping[physics.object_dof.ravel()] *= UNPUSHED_DAMPING_FACTOR
        if config.unheld_contacts == "sensed":
            # Touches found where the geoms touch, none acting (WorldConfig.unheld_contacts):
            # every contact of this room is an object's (the hand's are with objects only).
            objects = [*physics.stick_geoms, *physics.toy_geoms]
            physics.model.ptr.geom_margin[objects] = SENSED_CONTACT_MARGIN
            physics.model.ptr.geom_gap[objects] = SENSED_CONTACT_GAP
        mismatches = physics.disagreements_with(config)
        if mismatches:
            raise ValueError(
                f"the MJCF model {path or 'models/playroom.xml'} and the WorldConfig disagree: "
                + "; ".join(mismatches)
            )
        return physics

    def disagreements_with(self, config: WorldConfig) -> list[str]:
        """Where the model's geometry differs from the config's numbers (1e-9 m or rad)."""
        m = self.model.ptr
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        site = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, n)  # noqa: E731
        key = m.key_qpos[self.home_key]
        upper_arm_yaw = 2.0 * np.arctan2(
            m.body_quat[body("upper_arm"), 3], m.body_quat[body("upper_arm"), 0]
        )
        model_numbers = {
            "segment_lengths[0]": m.body_pos[body("forearm"), 0],
            "segment_lengths[1]": m.body_pos[body("hand_link"), 0],
            "segment_lengths[2]": m.site_pos[site("hand"), 0],
            "arm_rest_offset": upper_arm_yaw,
            "stick_length": m.site_pos[site("stick_tip"), 0],
            "stick_start_handle[0]": key[self.object_qpos[0, 0]],
            "stick_start_handle[1]": key[self.object_qpos[0, 1]],
            "stick_start_angle": key[self.object_qpos[0, 2]],
        }
        config_numbers = {
            "segment_lengths[0]": config.segment_lengths[0],
            "segment_lengths[1]": config.segment_lengths[1],
            "segment_lengths[2]": config.segment_lengths[2],
            "arm_rest_offset": config.arm_rest_offset,
            "stick_length": config.stick_length,
            "stick_start_handle[0]": config.stick_start_handle[0],
            "stick_start_handle[1]": config.stick_start_handle[1],
            "stick_start_angle": config.stick_start_angle,
        }
        return [
            f"{name}: model {model_numbers[name]:.6g}, config {value:.6g}"
            for name, value in config_numbers.items()
            if abs(model_numbers[name] - value) > 1e-9
        ]

    def _cache_indices(self) -> None:
        m = self.model.ptr
        self._mj_model = m
        self._mj_data = self.data.ptr
        site = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, n)  # noqa: E731
        geom = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        joint = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)  # noqa: E731
        self.hand_site = site("hand")
        self.handle_site = site("stick_handle")
        self.tip_site = site("stick_tip")
        self._hand_handle_sites = np.array([self.hand_site, self.handle_site])
        self.hand_geom = geom("hand")
        self.handle_geom = geom("stick_handle")
        self.tip_geom = geom("stick_tip")
        self.stick_geoms = np.array([geom(n) for n in ("stick_handle", "stick_shaft", "stick_tip")])
        self.toy_geoms = np.array([geom(t) for t in TOYS])
        self.toy_bodies = np.array([body(t) for t in TOYS])
        self.stick_body = body("stick")
        self.object_bodies = np.array([body(o) for o in OBJECTS])
        self.hand_body = body("hand_link")
        self.caregiver_mocap = m.body_mocapid[body("caregiver")]
        self.caregiver_hand_mocap = m.body_mocapid[body("caregiver_hand")]
        self.arm_qpos = np.array([m.jnt_qposadr[joint(j)] for j in ARM_JOINTS])
        self.arm_dof = np.array([m.jnt_dofadr[joint(j)] for j in ARM_JOINTS])
        # qpos addresses of (x, y, yaw) of each object, rows in OBJECTS order.
        self.object_qpos = np.array(
            [[m.jnt_qposadr[joint(f"{o}_{a}")] for a in ("x", "y", "yaw")] for o in OBJECTS]
        )
        self.object_dof = np.array(
            [[m.jnt_dofadr[joint(f"{o}_{a}")] for a in ("x", "y", "yaw")] for o in OBJECTS]
        )
        self.home_key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
        sensor = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, n)  # noqa: E731
        missing = [n for n in GRASP_CONTACTS if sensor(n) < 0]
        if missing:
            raise ValueError(
                f"the MJCF model has no contact sensor named {', '.join(missing)}: the physical "
                "grasp reads them (see the <sensor> section of models/playroom.xml)"
            )
        # sensordata addresses of GRASP_CONTACTS (each sensor one number).
        self.grasp_contact_adr = np.array([m.sensor_adr[sensor(n)] for n in GRASP_CONTACTS])
        # Flat views of the position arrays and the flat indices of the tracked x, y values:
        # one `take` each reads them (read every control step; fancy indexing of the 2-D
        # arrays cost several times more). The views live as long as this data.
        d = self._mj_data
        self._site_xpos_flat = d.site_xpos.reshape(-1)
        self._xpos_flat = d.xpos.reshape(-1)
        self._hand_handle_flat = (3 * self._hand_handle_sites[:, None] + [0, 1]).ravel()
        self._toys_flat = (3 * self.toy_bodies[:, None] + [0, 1]).ravel()
        self._mocap_pos_flat = d.mocap_pos.reshape(-1)
        self._handle_xy = slice(3 * self.handle_site, 3 * self.handle_site + 2)
        self._caregiver_xy = slice(3 * self.caregiver_mocap, 3 * self.caregiver_mocap + 2)
        # The joints' addresses as slices where they are consecutive (they are in
        # models/playroom.xml): a slice reads and writes qpos several times faster.
        self._arm_qpos = _as_slice(self.arm_qpos)
        self._object_qpos = _as_slice(self.object_qpos)
        self._object_dof = _as_slice(self.object_dof)
        self._arm_dof = _as_slice(self.arm_dof)
        self._object_shape = self.object_qpos.shape
        # What the compiled control steps write (sim/compiled_steps.py).
        self._caregiver_hand_row = d.mocap_pos[self.caregiver_hand_mocap]
        self._warning_numbers = d.warning.number  # a view: built once, read every movement
        self._disable_flags: np.ndarray | None = None  # found at the first compiled step
        self._rest_states: np.ndarray | None = None  # room for two states, at the first one
        # Control steps the compiled loop has computed (the others found the room at rest).
        self.control_steps_computed = np.zeros(1, dtype=np.int64)

    def _reload_from_data(self, data) -> None:
        super()._reload_from_data(data)
        self._cache_indices()

    # Measurements -------------------------------------------------------------------------
    def hand_position(self) -> np.ndarray:
        """(2,) position of the hand site."""
        return self._mj_data.site_xpos[self.hand_site, :2].copy()

    def tracked_positions(self) -> np.ndarray:
        """(5, 2) positions of hand, stick handle, toy1, toy2, toy3: the sensory objects."""
        out = np.empty((5, 2))
        self._read_tracked(out)
        return out

    def write_tracked_positions(self, out: np.ndarray) -> None:
        """`tracked_positions()` written into `out`, a C-contiguous (5, 2) float64 array (a
        movement's row: read at every control step)."""
        self._read_tracked(out)

    def _read_tracked(self, out: np.ndarray) -> None:
        flat = out.reshape(-1)  # a view: out is contiguous
        self._site_xpos_flat.take(self._hand_handle_flat, out=flat[:4])
        self._xpos_flat.take(self._toys_flat, out=flat[4:])

    def context_positions(self) -> np.ndarray:
        """(10,) stick handle, toy1, toy2, toy3 and caregiver x, y: the agent's context."""
        out = np.empty(10)
        out[:2] = self._site_xpos_flat[self._handle_xy]
        out[2:8] = self._xpos_flat.take(self._toys_flat)
        out[8:] = self._mocap_pos_flat[self._caregiver_xy]
        return out

    def hand_angle(self) -> float:
        """Orientation of the last segment in the plane (rad), as the protocol defines it."""
        return float(self.arm_angles().sum() + self.config.arm_rest_offset)

    def arm_angles(self) -> np.ndarray:
        """(3,) joint angles relative to rest (rad)."""
        return self._mj_data.qpos[self._arm_qpos].copy()

    def stick_handle(self) -> np.ndarray:
        """(2,) position of the stick's handle end."""
        return self._mj_data.site_xpos[self.handle_site, :2].copy()

    def stick_tip(self) -> np.ndarray:
        """(2,) position of the stick's far end, which catches toys."""
        return self._mj_data.site_xpos[self.tip_site, :2].copy()

    def toy_positions(self) -> np.ndarray:
        """(3, 2) positions of toy1, toy2, toy3."""
        return self._xpos_flat.take(self._toys_flat).reshape(len(TOYS), 2)

    def caregiver_position(self) -> np.ndarray:
        """(2,) position of the caregiver."""
        return self._mj_data.mocap_pos[self.caregiver_mocap, :2].copy()

    def object_poses(self) -> np.ndarray:
        """(4, 3) x, y, yaw of stick (handle), toy1, toy2, toy3, straight from the joints."""
        return self._mj_data.qpos[self._object_qpos].reshape(self._object_shape).copy()

    def set_object_poses(self, poses: np.ndarray) -> None:
        """Place the objects (4, 3) at rest and update the kinematics."""
        d = self._mj_data
        d.qpos[self._object_qpos] = poses.reshape(-1)
        d.qvel[self._object_dof] = 0.0
        mujoco.mj_kinematics(self._mj_model, self._mj_data)

    def stop_objects(self) -> None:
        """The stick's and the toys' velocities to zero."""
        self._mj_data.qvel[self._object_dof] = 0.0

    def rest_arm(self) -> None:
        """The arm back at rest, still, with no control; the kinematics updated."""
        d = self._mj_data
        d.qpos[self._arm_qpos] = 0.0
        d.qvel[self._arm_dof] = 0.0
        d.ctrl[:] = 0.0
        mujoco.mj_kinematics(self._mj_model, d)

    def advance(self, nstep: int) -> None:
        """`nstep` physics steps exactly as dm_control's `step` takes them (its legacy order:
        mj_step2, then nstep - 1 mj_step, then mj_step1, so that position-dependent fields are
        current), without its per-call check of MuJoCo's warnings: callers that step many
        times compare `warning_counts` once, before and after."""
        m, d = self._mj_model, self._mj_data
        mujoco.mj_step2(m, d)
        if nstep > 1:
            mujoco.mj_step(m, d, nstep - 1)
        mujoco.mj_step1(m, d)

    def control_steps(
        self,
        start: int,
        arm_targets: np.ndarray,
        brought: np.ndarray | None,
        positions: np.ndarray,
        watched: np.ndarray,
        trace: MovementTrace | None = None,
        moved: np.ndarray | None = None,
    ) -> int:
        """Control steps `start`, `start` + 1, ... of a movement in compiled code, each
        CONTROL_SUBSTEPS physics steps taken as `advance` takes them: before each, the servos'
        targets arm_targets[k] (n, 3) (or, if empty, left as they are) and the caregiver's hand
        at brought[k] (n, 2), her path (or None: not moved); after each, the tracked
        positions in positions[k + 1] (n + 1, 5, 2). Returns the first step after which a
        sensor of GRASP_CONTACTS at the indices `watched` is positive, or n. With no targets
        and nothing brought, the steps after one that leaves the room's state as it found it
        (all at rest) are not computed: only the time moves (sim.compiled_steps). Only where
        sim.compiled_steps.AVAILABLE. Where `trace` is given, its rows k + 1 take the joints' and
        the mocap bodies' positions after each step k. `moved`: what her path sets (a view of
        the data, its first two numbers x, y: the caregiver's carrying says which,
        sim/grasping/carrying.py); None, her hand."""
        from sim.compiled_steps import DYNAMIC_STATE, control_steps, disable_flags_view

        if not positions.flags.c_contiguous:  # its rows are written through a flat view
            raise ValueError("positions must be a C-contiguous (n + 1, 5, 2) array")
        if self._disable_flags is None or self._rest_states is None:
            found = disable_flags_view(self._mj_model)
            self._disable_flags = np.empty(0, dtype=np.int32) if found is None else found
            size = mujoco.mj_stateSize(self._mj_model, DYNAMIC_STATE)
            self._rest_states = np.empty((2, size))
        d = self._mj_data
        return control_steps(
            self._mj_model._address,
            d._address,
            CONTROL_SUBSTEPS,
            start,
            arm_targets,
            d.ctrl,
            _NOT_BROUGHT if brought is None else brought,
            self._caregiver_hand_row if moved is None else moved,
            self._site_xpos_flat,
            self._hand_handle_flat,
            self._xpos_flat,
            self._toys_flat,
            positions.reshape(len(positions), -1),
            d.sensordata,
            self.grasp_contact_adr[watched],
            self._disable_flags,
            self._rest_states,
            self._warning_numbers,
            self._mj_model.opt.timestep,
            self.control_steps_computed,
            d.qpos,
            self._mocap_pos_flat,
            _NOT_TRACED_QPOS if trace is None else trace.qpos,
            _NOT_TRACED_MOCAP
            if trace is None
            else trace.mocap_pos.reshape(len(trace.mocap_pos), -1),
        )

    def integration_state(self) -> np.ndarray:
        """MuJoCo's integration state (mjSTATE_INTEGRATION): what reproduces the room's next
        step, and what a checkpoint keeps."""
        m, d = self._mj_model, self._mj_data
        state = np.empty(mujoco.mj_stateSize(m, INTEGRATION_STATE))
        mujoco.mj_getState(m, d, state, INTEGRATION_STATE)
        return state

    def restore_integration_state(self, state: np.ndarray) -> None:
        """Put back an `integration_state`, everything derived from it computed."""
        m, d = self._mj_model, self._mj_data
        mujoco.mj_setState(m, d, state, INTEGRATION_STATE)
        mujoco.mj_forward(m, d)

    def warning_counts(self) -> np.ndarray:
        """(mjNWARNING,) how often MuJoCo has warned of each kind (a diverging state warns)."""
        return self._warning_numbers.copy()

    def grasp_contacts(self) -> np.ndarray:
        """(7,) how many contacts MuJoCo found between each pair of GRASP_CONTACTS, current
        after every step as the contact list is."""
        return self._mj_data.sensordata.take(self.grasp_contact_adr)

    def touching_pairs(self) -> np.ndarray:
        """(n, 2) geom ids of the pairs MuJoCo reports in contact now."""
        d = self._mj_data
        if d.ncon == 0:
            return np.empty((0, 2), dtype=int)
        return d.contact.geom[: d.ncon].copy()


def _as_slice(indices: np.ndarray) -> slice | np.ndarray:
    """The flat `indices` as a slice if they are consecutive and increasing, else themselves."""
    flat = np.asarray(indices).reshape(-1)
    if flat.size and (np.diff(flat) == 1).all():
        return slice(int(flat[0]), int(flat[-1]) + 1)
    return flat
