r"""The MuJoCo plant: the same arm, the same law, a second and independent simulator.

:class:`MujocoPlant` is a :class:`~twolink_pin.plant.Plant` (every option of the Pinocchio plant,
meaning the same) whose accelerations come from MuJoCo: the robot's URDF compiled once, in
memory (:mod:`twolink_pin.mujoco_model`), with the arm's effects MuJoCo has and Pinocchio has not
(:mod:`twolink_pin.arm_effects`: dry friction as a constraint, soft joint limits, its
integrators). It registers itself as the engine ``mujoco`` (``--plant mujoco``,
``PlantOptions(engine="mujoco")``); nothing above the simulation learns which engine ran.

**What "MuJoCo's RK4" is here.** With ``integrator="rk4"`` (the default) the engine's classical
RK4 advances the run, and each of its four stages asks MuJoCo for ``q̈`` at the stage's state:
``qpos``, ``qvel`` and the stage's torque written into one ``MjData``, ``mj_forward``, ``qacc``
read. This is the computation ``mj_step`` does with ``integrator="RK4"`` and the law installed
as ``mjcb_control`` (MuJoCo's ``mj_RK4`` calls ``mj_forward``'s stages, and through them the
control callback, at ``t``, ``t + dt/2`` twice and ``t + dt``, and combines them with the same
Butcher tableau), done in the engine so that the law's own state ``z``, the plant's events and a
batch of runs are integrated the same way on both plants; ``tests/test_mujoco_plant.py`` checks
that ``mj_step`` with a control callback gives the same run. With every extra effect off the two
plants then integrate the same ODE with the same method and step: they differ only by the
rounding of two forward-dynamics algorithms (MuJoCo's CRB and sparse ``LDLᵀ`` against
Pinocchio's ABA: ~1e-15 relative per evaluation), which a stable closed loop does not amplify —
hence the equality to 1e-8 rad over 30 s.

With ``integrator="euler"`` or ``"implicitfast"`` MuJoCo steps the run itself (``mj_step``):
these integrators evaluate the forces once per step, so the law is held over each step (as
``--control-period dt``) and ``z ← z + dt ż``; joint damping is then integrated implicitly, as
MuJoCo does. An unstable run (MuJoCo's ``mjWARN_BADQACC``, a NaN) fails at its time with
MuJoCo's cause (:meth:`MujocoDynamics.failure`), never a reset: automatic reset is off.

**Batches.** N runs step N simulations of one ``mujoco.batch.Batch`` (MuJoCo 4's batch API): at
each stage the N states and torques are written into the batch's state rows in one numpy copy
each and one ``Batch.forward()`` call runs the N forward passes on its thread pool, the GIL
released; the law is evaluated once for the N runs, as on Pinocchio's ``abaInParallel``.
(``mujoco.rollout`` steps open-loop controls: it cannot call a Python law per stage.)
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable
from dataclasses import KW_ONLY, dataclass, field
from typing import Any, ClassVar

import numpy as np

from twolink_pin.arm_effects import MUJOCO_ONLY, SOLIMP, SOLREF, per_joint
from twolink_pin.dynamics import smooth_sign
from twolink_pin.errors import InvalidParameterError
from twolink_pin.mujoco_contact import MujocoContact, add_scene, set_contact_properties
from twolink_pin.mujoco_model import compile_model, require_mujoco
from twolink_pin.plant import Plant, register_engine

MAX_ACCELERATION = 1e10
"""MuJoCo's ``mjMAXVAL`` [rad/s²]: a larger or NaN ``q̈`` is its ``mjWARN_BADQACC``."""


@dataclass(frozen=True, eq=False)
class MujocoPlant(Plant):
    """The arm in MuJoCo (see the module docstring); fields beyond :class:`Plant`'s:

    Attributes:
        frictionloss: Dry friction per joint [N·m], shape (nv,) (MuJoCo's ``frictionloss``).
        soft_limits: The position ranges as MuJoCo's soft joint limits (None: on).
        solref: The soft limits' time constant [s] and damping ratio (None: MuJoCo's).
        solimp: Their impedance (d0, dwidth, width [rad], midpoint, power) (None: MuJoCo's).
        integrator: ``rk4`` (the engine's, law per stage), ``euler`` or ``implicitfast``
            (MuJoCo's ``mj_step``, the law held over each step).
        carried: Payload carried at the end effector beyond the robot's [kg] (after a payload step).
        mj_model: The compiled ``MjModel`` (read it; each run works on its own copy).
    """

    engine: ClassVar[str] = "mujoco"
    takes: ClassVar[tuple[str, ...]] = MUJOCO_ONLY
    _: KW_ONLY
    frictionloss: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # None: zeros
    soft_limits: bool | None = None
    solref: tuple[float, ...] | None = None
    solimp: tuple[float, ...] | None = None
    integrator: str = "rk4"
    carried: float = 0.0
    mj_model: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "frictionloss", per_joint("frictionloss", self.frictionloss, self.robot.nv))
        object.__setattr__(self, "soft_limits", self.soft_limits is not False)
        object.__setattr__(self, "solref", tuple(self.solref or SOLREF))
        object.__setattr__(self, "solimp", tuple(self.solimp or SOLIMP))
        if self.integrator not in ("rk4", "euler", "implicitfast"):
            raise InvalidParameterError("integrator", self.integrator, "rk4, euler or implicitfast")
        model = compile_model(
            self.robot,
            armature=self.armature,
            damping=self.joint_damping,
            frictionloss=self.frictionloss,
            soft_limits=bool(self.soft_limits),
            solref=self.solref or SOLREF,
            solimp=self.solimp or SOLIMP,
            saturate=self.saturate,
            payload=self.carried,
            integrator=self.integrator,
            scene=None if self.scene is None else add_scene(self.robot, self.scene),
        )
        if self.scene is not None:
            set_contact_properties(require_mujoco(), model, self.scene)
        object.__setattr__(self, "mj_model", model)

    @property
    def law_per_stage(self) -> bool:
        """RK4 is the engine's: the law at each stage; MuJoCo's Euler and implicitfast hold it."""
        return self.integrator == "rk4"

    def dynamics(self, runs: int, threads: int | None) -> Any:
        """``q̈`` of ``runs`` runs from MuJoCo: one ``MjData`` for one run, a ``Batch`` for N."""
        stepped = self.integrator != "rk4"
        if runs == 1:
            return SteppedDynamics(self) if stepped else MujocoDynamics(self).fast()
        return (
            SteppedBatchDynamics(self, runs, threads) if stepped else MujocoBatchDynamics(self, runs, threads)
        )

    def contact_model(self, runs: int, step: float | None = None) -> MujocoContact | None:  # type: ignore[override]
        """MuJoCo's own contact with the scene, read from the runs' ``MjData``
        (:class:`~twolink_pin.mujoco_contact.MujocoContact`; MuJoCo applies it: no ``tau``)."""
        if self.scene is None:
            return None
        return MujocoContact(
            self.mj_model, self.robot, self.scene, runs, step if self.law_per_stage else None
        )

    def after_payload(self) -> MujocoPlant:
        """This plant with its payload step's mass carried: MuJoCo's model recompiled with it."""
        step = self.payload_step
        assert step is not None
        model = step.model(self.model, self.robot.ee_frame_id)
        return dataclasses.replace(self, model=model, carried=self.carried + step.mass)

    def acceleration(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint acceleration [rad/s²] of one state under commanded torque ``tau`` [N·m] (MuJoCo's)."""
        return MujocoDynamics(self)(
            np.asarray(q, float)[None], np.asarray(v, float)[None], np.asarray(tau, float)[None]
        )[0]

    def describe(self, values: bool = False) -> str:
        """``MuJoCo (integrator), `` before the Pinocchio plant's words."""
        return f"MuJoCo {self.integrator}, " + super().describe(values)

    def effects_described(self, values: bool = False) -> list[str]:
        """The effects of :class:`Plant`, then dry friction and the soft limits."""
        parts = super().effects_described(values)
        if self.frictionloss.any():
            text = "frictionloss"
            if values:
                source = dict(self.effect_sources).get("frictionloss")
                text += f" ({', '.join(f'{x:g}' for x in self.frictionloss)}) N·m" + (
                    f" from {source}" if source else ""
                )
            parts.append(text)
        if self.soft_limits and (values or self.solref != SOLREF or self.solimp != SOLIMP):
            parts.append(
                f"soft limits (solref {','.join(f'{x:g}' for x in self.solref)}, "  # type: ignore[union-attr]
                f"solimp {','.join(f'{x:g}' for x in self.solimp)})"  # type: ignore[union-attr]
            )
        elif not self.soft_limits:
            parts.append("no soft limits")
        return parts


class MujocoDynamics:
    """``q̈`` [rad/s²] of one run, shape (1, nv), from MuJoCo's ``mj_forward`` (see the module docstring)."""

    def __init__(self, plant: MujocoPlant) -> None:
        self._mujoco = mujoco = require_mujoco()
        self._forward = mujoco.mj_forward
        self.model = model = copy.copy(plant.mj_model)  # its own options (the step)
        self.data = data = mujoco.MjData(model)
        self._datas = [data]
        nv = model.nv
        self._qpos, self._qvel = data.qpos.reshape(1, nv), data.qvel.reshape(1, nv)
        self._qacc, self._applied = data.qacc.reshape(1, nv), data.qfrc_applied.reshape(1, nv)
        self._ctrl = data.ctrl.reshape(1, nv) if plant.saturate else None
        friction = plant.friction
        self._friction = (
            None if friction is None else (np.array([friction.viscous]), np.array([friction.coulomb]))
        )
        self._smoothing = 0.0 if friction is None else friction.smoothing

    def __call__(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> np.ndarray:
        """``external``: a joint torque [N·m] from outside the motors (a wrench's ``Jᵀ F``), never
        clamped by the motors' force range, (1, nv) or None."""
        self._load(q, v, tau, external)
        self._forward(self.model, self.data)
        return self._qacc.copy()

    def fast(self) -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
        """This call as a closure over its arrays (no attribute look-ups: it runs four times per
        step), carrying :meth:`failure`; the plain torque path only (no clamp, no friction),
        else the method itself."""
        if self._ctrl is not None or self._friction is not None:
            return self
        qpos, qvel, applied, qacc = self._qpos, self._qvel, self._applied, self._qacc
        forward, model, data = self._forward, self.model, self.data

        def accel(
            q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
        ) -> np.ndarray:
            qpos[...] = q
            qvel[...] = v
            applied[...] = tau if external is None else tau + external
            forward(model, data)
            return qacc.copy()

        accel.failure = self.failure  # type: ignore[attr-defined]
        accel.datas = self.datas  # type: ignore[attr-defined]
        accel.model = model  # type: ignore[attr-defined]
        accel.inputs = self.inputs  # type: ignore[attr-defined]
        accel.resume = self.resume  # type: ignore[attr-defined]
        return accel

    def _load(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> None:
        """The state and the torque into ``MjData``: with saturation the motors take ``τ`` (their
        force range clamps it) and ``0·τ`` goes into ``qfrc_applied``, so that a non-finite
        torque, which MuJoCo would replace by 0 (``mjWARN_BADCTRL``), fails the run as on the
        Pinocchio plant; the toolkit's friction ``−f(q̇)`` and the ``external`` torque (never
        clamped) go into ``qfrc_applied`` too."""
        self._qpos[...] = q
        self._qvel[...] = v
        ctrl = self._ctrl
        if ctrl is not None:
            ctrl[...] = tau
            applied = 0.0 * tau
        else:
            applied = tau
        if self._friction is not None:
            viscous, coulomb = self._friction
            applied = applied - (viscous * v + coulomb * smooth_sign(v, self._smoothing))
        self._applied[...] = applied if external is None else applied + external

    def datas(self) -> list[Any]:
        """The run's ``MjData`` (its contacts: :class:`~twolink_pin.mujoco_contact.MujocoContact`)."""
        return self._datas

    def inputs(self) -> tuple[np.ndarray, ...]:
        """The last call's ``qpos``, ``qvel``, ``qfrc_applied`` and ``ctrl`` rows, (1, ·) each."""
        data = self.data
        return data.qpos[None], data.qvel[None], data.qfrc_applied[None], data.ctrl[None]

    def resume(self, previous: Any) -> None:
        """Take over from ``previous`` (the plant before a payload step): its last call's inputs
        evaluated here, so that the contact read before this plant's first call is its own."""
        _resume(self.data.qpos, self.data.qvel, self.data.qfrc_applied, self.data.ctrl, previous)
        self._forward(self.model, self.data)

    def failure(self, run: int) -> str | None:
        """MuJoCo's own cause of a failed run: its warnings, or its last ``q̈`` if non-finite or huge."""
        return _warned(self._mujoco, self.data.warning, self.data.qacc)


class SteppedDynamics(MujocoDynamics):
    """One run that MuJoCo's ``euler`` or ``implicitfast`` steps (``mj_step``, the law held)."""

    def held_step(
        self,
        q: np.ndarray,
        v: np.ndarray,
        z: np.ndarray,
        tau: np.ndarray,
        dz: np.ndarray,
        steps: Any,
        nz: int,
        external: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One ``mj_step`` of ``steps.dt`` [s] from ``(q, v)`` under the held torque (and the held
        ``external`` torque, never clamped); ``z ← z + dt ż``."""
        model = self.model
        if model.opt.timestep != steps.dt:
            model.opt.timestep = steps.dt
        self._load(q, v, tau, external)
        self._mujoco.mj_step(model, self.data)
        return self._qpos.copy(), self._qvel.copy(), (z + steps.h * dz if nz else z)


class MujocoBatchDynamics:
    """``q̈`` [rad/s²] of N runs, shape (N, nv): one ``mujoco.batch.Batch.forward`` per call."""

    def __init__(self, plant: MujocoPlant, runs: int, threads: int | None) -> None:
        self._mujoco = require_mujoco()
        from mujoco import batch

        self.model = model = copy.copy(plant.mj_model)
        # persistent: each run's whole MjData kept, its contacts read by get_data (a scene)
        self.batch = b = batch.Batch(
            model, nsim=runs, nthread=max(1, threads or 1), persistent=plant.scene is not None
        )
        self._qpos, self._qvel, self._applied = b.bind("qpos"), b.bind("qvel"), b.bind("qfrc_applied")
        self._ctrl = b.bind("ctrl") if plant.saturate else None
        self._qacc = b.bind("qacc")
        self._plant = plant
        self._datas: list[Any] | None = None
        self._ncon: np.ndarray | None = None
        friction = plant.friction
        self._friction = friction

    def __call__(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> np.ndarray:
        """As :meth:`MujocoDynamics.__call__`, (N, nv) rows."""
        self._load(q, v, tau, external)
        self.batch.forward()
        return self._qacc.copy()

    def _load(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, external: np.ndarray | None = None
    ) -> None:
        """As :meth:`MujocoDynamics._load`, every run's row at once."""
        self._qpos[...] = q
        self._qvel[...] = v
        if self._ctrl is not None:
            self._ctrl[...] = tau
            applied = 0.0 * tau
        else:
            applied = tau
        if self._friction is not None:
            applied = applied - self._friction.torque(v)
        self._applied[...] = applied if external is None else applied + external

    def datas(self) -> list[Any]:
        """Each run's ``MjData`` after the batch's last call, None for a run without contacts (its
        contacts: :class:`~twolink_pin.mujoco_contact.MujocoContact`; copied out of the batch)."""
        b = self.batch
        if self._datas is None:
            self._datas = [self._mujoco.MjData(self.model) for _ in range(b.nsim)]
            self._ncon = b.bind("ncon")
        ncon = self._ncon
        assert ncon is not None
        return [b.get_data(i, data) if n else None for i, (n, data) in enumerate(zip(ncon, self._datas))]

    def inputs(self) -> tuple[np.ndarray, ...]:
        """The last call's ``qpos``, ``qvel``, ``qfrc_applied`` and ``ctrl`` rows, (N, ·) each."""
        b = self.batch
        return b.bind("qpos"), b.bind("qvel"), b.bind("qfrc_applied"), b.bind("ctrl")

    def resume(self, previous: Any) -> None:
        """As :meth:`MujocoDynamics.resume`, every run."""
        qpos, qvel, applied, ctrl = self.inputs()
        _resume(qpos, qvel, applied, ctrl, previous)
        self.batch.forward()

    def failure(self, run: int) -> str | None:
        """MuJoCo's own cause of run ``run``'s failure (its warnings, or its last ``q̈``)."""
        return _warned(self._mujoco, self.batch.warning[run], self._qacc[run], counts_only=True)


class SteppedBatchDynamics(MujocoBatchDynamics):
    """N runs that MuJoCo's ``euler`` or ``implicitfast`` steps (``Batch.step``, the law held)."""

    def held_step(
        self,
        q: np.ndarray,
        v: np.ndarray,
        z: np.ndarray,
        tau: np.ndarray,
        dz: np.ndarray,
        steps: Any,
        nz: int,
        external: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One step of ``steps.dt`` [s] of every run under its held torque (and ``external``);
        ``z ← z + dt ż``."""
        model = self.model
        if model.opt.timestep != steps.dt:
            model.opt.timestep = steps.dt
            self.batch = _rebuilt(self.batch, model)
            b = self.batch
            self._qpos, self._qvel, self._applied = b.bind("qpos"), b.bind("qvel"), b.bind("qfrc_applied")
            self._ctrl = b.bind("ctrl") if self._ctrl is not None else None
            self._qacc = b.bind("qacc")
            self._datas = None  # the contacts' reads bound to the new batch
        self._load(q, v, tau, external)
        self.batch.step()
        return self._qpos.copy(), self._qvel.copy(), (z + steps.h * dz if nz else z)


def _resume(qpos: np.ndarray, qvel: np.ndarray, applied: np.ndarray, ctrl: np.ndarray, previous: Any) -> None:
    """``previous``'s last inputs written into these arrays (the same arm: the same sizes)."""
    for target, source in zip((qpos, qvel, applied, ctrl), previous.inputs(), strict=True):
        target[...] = source.reshape(target.shape)


def _rebuilt(old: Any, model: Any) -> Any:
    """A batch of ``model`` (its options changed) carrying ``old``'s state rows."""
    from mujoco import batch

    new = batch.Batch(model, nsim=old.nsim, nthread=old.nthread, persistent=old.persistent)
    new.state[...] = old.state
    return new


WARNINGS = {
    "mjWARN_BADQACC": "the acceleration became NaN or beyond 1e10 (mjWARN_BADQACC)",
    "mjWARN_BADQVEL": "the velocity became NaN or beyond 1e10 (mjWARN_BADQVEL)",
    "mjWARN_BADQPOS": "the position became NaN or beyond 1e10 (mjWARN_BADQPOS)",
    "mjWARN_BADCTRL": "a control became NaN (mjWARN_BADCTRL)",
}
"""MuJoCo's warnings of an unstable simulation, in words."""
HINT = (
    "the simulation went unstable: a stiff soft limit or damping for this step, or a law that drives "
    "it so; try --mujoco-integrator implicitfast or a smaller --dt"
)


def _warned(mujoco: Any, warning: Any, qacc: np.ndarray, counts_only: bool = False) -> str | None:
    """What MuJoCo saw go wrong: the first of :data:`WARNINGS` it counted (``warning``: an
    ``MjData.warning`` array of structs, or a batch's (nwarning, 2) rows ``(lastinfo, number)``),
    else a last ``q̈`` that is NaN or beyond :data:`MAX_ACCELERATION`; None if neither."""
    for name, text in WARNINGS.items():
        index = int(getattr(mujoco.mjtWarning, name))
        count = int(warning[index][1]) if counts_only else int(warning[index].number)
        if count:
            return f"MuJoCo: {text}; {HINT}"
    qacc = np.asarray(qacc)
    if not (np.abs(qacc) < MAX_ACCELERATION).all():
        return f"MuJoCo's q̈ = {np.round(qacc.ravel(), 3).tolist()} rad/s² (NaN or beyond 1e10); {HINT}"
    return None


register_engine("mujoco", MujocoPlant)

__all__ = [
    "MAX_ACCELERATION",
    "MujocoBatchDynamics",
    "MujocoDynamics",
    "MujocoPlant",
    "SteppedBatchDynamics",
    "SteppedDynamics",
]
