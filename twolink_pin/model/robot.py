"""Loading a robot arm from URDF into Pinocchio.

:func:`load_robot` resolves a robot name or a URDF path (:mod:`twolink_pin.model.catalog`),
validates the file (:mod:`twolink_pin.model.urdf_validation`), builds the Pinocchio model,
optionally adds a point-mass payload at the end effector, and reads everything else the
toolkit needs from the model: link lengths, torque limits and the parameters ``p`` of the
robot's parameter map. The robot's :class:`~twolink_pin.model.profile.RobotProfile` rides
along (its gain presets, default trajectory, plant friction).
"""

from __future__ import annotations

import dataclasses
import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.model.base_parameters import BaseParameterMap
from twolink_pin.model.catalog import example_robot_urdf, resolve
from twolink_pin.model.home import choose_home
from twolink_pin.model.inertia_repair import InertiaRepair
from twolink_pin.model.parameters import ParameterMap
from twolink_pin.model.profile import RobotProfile, default_q0_offset
from twolink_pin.model.urdf_validation import CheckedURDF, check_urdf_file

DEFAULT_EE_FRAME = "ee_link"

__all__ = ["DEFAULT_EE_FRAME", "RobotModel", "example_robot_urdf", "load_robot", "twolink_urdf_path"]


def twolink_urdf_path() -> Path:
    """Path of the shipped ``twolink.urdf`` (works from a checkout and an installed wheel)."""
    return resolve("twolink")[0]


@dataclass(frozen=True)
class RobotModel:
    """A loaded arm: Pinocchio model plus what the toolkit reads from it.

    Create a fresh ``pin.Data`` per user (plant, controller, ...) with :meth:`create_data`.
    """

    model: pin.Model
    """Pinocchio model (kinematic tree and inertias, payload included)."""
    urdf_path: Path
    """The URDF file the model was built from."""
    ee_frame_id: int
    """Index of the end-effector frame in ``model.frames``."""
    payload: float
    """Point mass added at the end effector [kg]."""
    parameter_map: ParameterMap
    """Map from Pinocchio's inertial parameters to ``p``."""
    link_lengths: np.ndarray = field(repr=False)
    """Distance between successive joints, the last to the end effector [m], shape (nv,)."""
    torque_limits: np.ndarray = field(repr=False)
    """Motor torque limit of each joint from the URDF ``<limit effort>`` [N·m], shape (nv,);
    ``inf`` where the URDF gives none (effort 0 or absent)."""
    p: np.ndarray = field(repr=False)
    """True parameters of the map (for the twolink p1, p2, p3 [kg·m²])."""
    profile: RobotProfile = field(repr=False, default_factory=lambda: RobotProfile("robot"))
    """The robot's name and defaults (gain presets, trajectory, plant friction)."""
    notes: tuple[str, ...] = field(repr=False, default=())
    """What the loader accepted with a note (a static link's mass 0, a thin rod's zero moment,
    how the home was chosen): the commands print them."""
    repairs: tuple[InertiaRepair, ...] = field(repr=False, default=())
    """The inertias ``repair_inertias`` replaced (:mod:`~twolink_pin.model.inertia_repair`)."""
    urdf_text: str = field(repr=False, default="")
    """The URDF document the model was built from (repaired inertias written in): what a second
    engine compiles, so that both plants simulate the same arm."""

    @property
    def name(self) -> str:
        """The robot's short name (catalog name or URDF file stem)."""
        return self.profile.name

    @property
    def gain_presets(self) -> Mapping[str, Mapping[str, Any]]:
        """Gains per law name that laws built on this robot use by default."""
        return self.profile.gain_presets

    @property
    def home(self) -> np.ndarray:
        """A configuration [rad] inside the joint limits that default trajectories swing about
        and robot-derived gains are scaled at: the profile's ``home``, else the one the loader
        chose (dexterous, near the middle of the ranges: ``profile.home_source`` says how,
        :mod:`~twolink_pin.model.home`); the middle of each range for a model built by hand."""
        if self.profile.home is not None:
            return np.array(self.profile.home, dtype=float)
        lower, upper = np.array(self.model.lowerPositionLimit), np.array(self.model.upperPositionLimit)
        finite = np.isfinite(lower) & np.isfinite(upper)
        return np.where(finite, 0.5 * (np.where(finite, lower, 0.0) + np.where(finite, upper, 0.0)), 0.0)

    @property
    def urdf_friction(self) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
        """The URDF's joint friction ``(damping [N·m·s/rad], friction [N·m])`` per joint, from
        its ``<dynamics damping friction>`` (read by Pinocchio's parser into ``model.damping``
        and ``model.friction``); None when every value is 0 or absent."""
        damping = tuple(float(x) for x in self.model.damping)
        coulomb = tuple(float(x) for x in self.model.friction)
        if not any(damping) and not any(coulomb):
            return None
        return damping, coulomb

    @property
    def nq(self) -> int:
        """Size of the configuration vector."""
        return int(self.model.nq)

    @property
    def nv(self) -> int:
        """Number of degrees of freedom."""
        return int(self.model.nv)

    @property
    def ee_frame(self) -> str:
        """Name of the end-effector frame."""
        return str(self.model.frames[self.ee_frame_id].name)

    def create_data(self) -> pin.Data:
        """A new ``pin.Data`` for this model."""
        return self.model.createData()


def _refusal(
    profile: RobotProfile, path: Path, key: str, element: str, value: object, reason: str
) -> Exception:
    """A profile value the model refuses: named ``FILE: key`` for a profile file's
    (:class:`InvalidParameterError`), else as the URDF's element (:class:`InvalidURDFError`)."""
    if profile.file is not None:
        return InvalidParameterError(f"{profile.file}: {key}", value, reason)
    return InvalidURDFError(str(path), element, reason)


def _end_effector_frame(model: pin.Model, ee_frame: str | None, path: Path, profile: RobotProfile) -> int:
    """The end-effector frame's index: ``ee_frame`` (the caller's), else the profile's, else
    ``ee_link``, else the last frame on the last joint."""
    from_profile = ee_frame is None
    ee_frame = ee_frame if ee_frame is not None else profile.ee_frame
    if ee_frame is not None:
        if not model.existFrame(ee_frame):
            names = [f.name for f in model.frames]
            if not from_profile:
                raise InvalidURDFError(str(path), f"frame '{ee_frame}'", f"no such frame; frames are {names}")
            reason = f"a frame of {path.name}; no such frame, frames are {names}"
            raise _refusal(profile, path, "end_effector", f"frame '{ee_frame}'", ee_frame, reason)
        matches = [i for i, f in enumerate(model.frames) if f.name == ee_frame]
        bodies = [i for i in matches if model.frames[i].type == pin.FrameType.BODY]
        return (bodies or matches)[0]  # a link's frame before a fixed joint of the same name
    if model.existFrame(DEFAULT_EE_FRAME):
        return int(model.getFrameId(DEFAULT_EE_FRAME))
    # Otherwise: the last frame attached to the last joint.
    last_joint = model.njoints - 1
    candidates = [i for i, f in enumerate(model.frames) if f.parentJoint == last_joint]
    return candidates[-1]


def _link_lengths(model: pin.Model, ee_frame_id: int) -> np.ndarray:
    lengths = [float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(2, model.njoints)]
    lengths.append(float(np.linalg.norm(model.frames[ee_frame_id].placement.translation)))
    return np.array(lengths)


SINGULAR_INERTIA = 1e-12
"""A joint whose ``M_jj`` is below this [kg·m²] moves no inertia: ``M(q)`` is singular."""


def _child_link(model: pin.Model, joint: int) -> str:
    for frame in model.frames:
        if frame.parentJoint == joint and frame.type == pin.FrameType.BODY:
            return str(frame.name)
    return str(model.names[joint])


def _check_inertias(model: pin.Model, path: Path, payload: float) -> None:
    """Every body's inertial parameters finite (a huge payload can overflow them)."""
    for j in range(1, model.njoints):
        if not np.all(np.isfinite(model.inertias[j].toDynamicParameters())):
            if payload > 0:
                raise InvalidParameterError(
                    "payload",
                    payload,
                    f"a mass [kg] that keeps the inertia of link '{_child_link(model, j)}' finite",
                )
            raise InvalidURDFError(
                str(path), f"link '{_child_link(model, j)}'", "non-finite inertial parameters"
            )


def _check_moves_inertia(model: pin.Model, path: Path) -> None:
    """``M(q)`` positive definite at the neutral and three seeded configurations: a joint that
    moves no mass (its link and every link after it massless) would make every run diverge at
    its first step with nothing to say why."""
    data = model.createData()
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    rng = np.random.default_rng(0)
    configurations = [pin.neutral(model)] + [
        rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi)) for _ in range(3)
    ]
    for q in configurations:
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        diagonal = np.diag(M)
        idle = [int(i) for i in np.flatnonzero(diagonal < SINGULAR_INERTIA)]
        if idle:
            joint = next(
                j
                for j in range(1, model.njoints)
                if model.idx_vs[j] <= idle[0] < model.idx_vs[j] + model.nvs[j]
            )
            raise InvalidURDFError(
                str(path),
                f"joint '{model.names[joint]}'",
                f"moves no mass or inertia (M = {diagonal[idle[0]]:.3g} kg·m²: its link "
                f"'{_child_link(model, joint)}' and every link after it are massless); expected an <inertial> "
                "with a mass > 0 on a link it moves",
            )
        try:
            np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            raise InvalidURDFError(
                str(path),
                "<robot>",
                f"the joint-space inertia M(q) is singular at q = {np.round(q, 4).tolist()} rad",
            ) from None


CONTINUOUS = "continuous"


def _revolute_continuous(text: str) -> tuple[str, tuple[str, ...]]:
    """``text`` with every continuous joint made revolute (one angle, unbounded: see
    :func:`_build_model`), and the names of those joints."""
    root = ET.fromstring(text)
    names = []
    for joint in root.iter("joint"):
        if joint.get("type") == CONTINUOUS:
            joint.set("type", "revolute")
            limit = joint.find("limit")
            if limit is None:
                limit = ET.SubElement(joint, "limit", {"effort": "0", "velocity": "0"})
            limit.set("lower", "-1")
            limit.set("upper", "1")
            names.append(str(joint.get("name")))
    if not names:
        return text, ()
    return ET.tostring(root, encoding="unicode"), tuple(names)


def _build_model(path: Path, profile: RobotProfile, checked: CheckedURDF) -> tuple[pin.Model, RobotProfile]:
    """The Pinocchio model of the checked URDF at ``path``, for tracking control, and the profile
    (its ``free_joints`` turned into locked ones):

    * a continuous joint becomes a revolute joint without position limits: one angle
      [rad] in ℝ instead of Pinocchio's (cos, sin) pair, so that ``nq == nv`` and a
      joint error is ``q − q_d`` (the dynamics are the same; the angle is not wrapped);
    * a joint whose lower and upper limits are equal (URDF's default 0 and 0 when the
      ``<limit>`` gives none, as in the double pendulum) has no position limit;
    * the profile's ``locked_joints`` are fixed at ``locked_positions``
      (``pin.buildReducedModel``: their links ride on the link before them).
    """
    text, continuous = _revolute_continuous(checked.text)
    try:
        model = pin.buildModelFromXML(text)
    except (ValueError, RuntimeError) as exc:  # validated already; keep any surprise readable
        raise InvalidURDFError(str(path), "<robot>", f"Pinocchio could not build a model: {exc}") from exc
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    for j in range(1, model.njoints):
        i, n = model.idx_qs[j], model.nqs[j]
        if model.names[j] in continuous or (n == 1 and lower[i] == upper[i]):
            lower[i : i + n], upper[i : i + n] = -np.inf, np.inf
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    _check_locked_positions(model, profile, path)
    if profile.free_joints is not None:
        profile = _free(model, profile, path)
    if profile.locked_joints:
        model = _lock(model, profile, path)
    if model.nv == 0:
        if profile.locked_joints and profile.file is not None:
            raise _refusal(
                profile,
                path,
                "locked",
                "<robot>",
                list(profile.locked_joints),
                f"at least one joint of {path.name} left free; these lock every one",
            )
        raise InvalidURDFError(str(path), "<robot>", "expected at least one moving joint, found none")
    if model.nq != model.nv:
        kinds = sorted({model.joints[j].shortname() for j in range(1, model.njoints) if model.nqs[j] != 1})
        raise InvalidURDFError(
            str(path),
            "<robot>",
            f"expected joints of one coordinate each (revolute, continuous, prismatic), got nq = {model.nq}, "
            f"nv = {model.nv} ({', '.join(kinds)})",
        )
    return model, profile


def _free(model: pin.Model, profile: RobotProfile, path: Path) -> RobotProfile:
    """``profile`` with every joint but its ``free_joints`` among its locked ones."""
    assert profile.free_joints is not None
    joints = [str(model.names[j]) for j in range(1, model.njoints)]
    for name in profile.free_joints:
        if name not in joints:
            raise _refusal(
                profile, path, "free", f"joint '{name}'", name, f"a joint of {path.name}; joints are {joints}"
            )
    for name in profile.locked_joints:
        if name not in joints:
            reason = f"a joint of {path.name} to lock; no such joint, joints are {joints}"
            raise _refusal(profile, path, "locked", f"joint '{name}'", name, reason)
        if name in profile.free_joints:
            reason = f"a joint not also listed in free (joint '{name}' is in both)"
            raise _refusal(profile, path, "locked", f"joint '{name}'", name, reason)
    given = dict(zip(profile.locked_joints, profile.locked_positions or (0.0,) * len(profile.locked_joints)))
    locked = [name for name in joints if name not in profile.free_joints]
    return dataclasses.replace(
        profile, locked_joints=tuple(locked), locked_positions=tuple(given.get(name, 0.0) for name in locked)
    )


def _check_locked_positions(model: pin.Model, profile: RobotProfile, path: Path) -> None:
    """Refuse a position the profile locks a joint at outside that joint's range."""
    for name, value in zip(profile.locked_joints, profile.locked_positions or ()):
        if not model.existJointName(name):
            continue  # named by the lock itself
        i = model.idx_qs[model.getJointId(name)]
        lower, upper = model.lowerPositionLimit[i], model.upperPositionLimit[i]
        if not lower <= value <= upper:
            reason = f"a position within joint '{name}''s range [{lower:g}, {upper:g}] rad (m if prismatic)"
            raise _refusal(profile, path, f"locked.{name}", f"joint '{name}'", value, reason)


def _check_sizes(model: pin.Model, profile: RobotProfile, path: Path) -> None:
    """Refuse a per-joint value of the profile whose count is not the free joints' (one value
    also for ``q0_offset``), naming the key, before a run meets it."""
    nv = model.nv
    what = f"per free joint, nv = {nv}"
    if profile.q0_offset is not None and len(profile.q0_offset) not in (1, nv):
        reason = f"one value [rad], or {nv} ({what})"
        raise _refusal(profile, path, "q0_offset", "q0_offset", list(profile.q0_offset), reason)
    accel = profile.acceleration_limits
    if accel is not None and (len(accel) != nv or not all(a > 0 for a in accel)):
        reason = f"{nv} values > 0 [rad/s²] ({what})"
        raise _refusal(profile, path, "acceleration_limits", "acceleration_limits", list(accel), reason)
    if profile.friction is not None:
        for key, values in zip(("viscous", "coulomb"), profile.friction):
            if len(values) != nv or not all(v >= 0 for v in values):
                reason = f"{nv} values >= 0 ({what})"
                raise _refusal(profile, path, f"friction.{key}", "friction", list(values), reason)
    effects = profile.effects
    for key in ("armature", "damping", "frictionloss"):
        given: tuple[float, ...] | None = None if effects is None else getattr(effects, key)
        if given is not None and len(given) != nv:
            raise _refusal(profile, path, f"effects.{key}", "effects", list(given), f"{nv} values ({what})")
    trajectory = profile.trajectory
    if trajectory is not None and trajectory.joint_points is not None:
        for point in trajectory.joint_points:
            if len(point) != nv:
                reason = f"points of {nv} joint positions [rad or m] ({what})"
                raise _refusal(profile, path, "trajectory.joint_points", "trajectory", list(point), reason)


def _lock(model: pin.Model, profile: RobotProfile, path: Path) -> pin.Model:
    ids = []
    for name in profile.locked_joints:
        if not model.existJointName(name):
            joints = list(model.names)[1:]
            reason = f"a joint of {path.name} to lock; no such joint, joints are {joints}"
            raise _refusal(profile, path, "locked", f"joint '{name}'", name, reason)
        ids.append(int(model.getJointId(name)))
    q = np.zeros(model.nq)
    positions = profile.locked_positions or (0.0,) * len(ids)
    for j, value in zip(ids, positions):
        i = model.idx_qs[j]
        q[i] = np.clip(value, model.lowerPositionLimit[i], model.upperPositionLimit[i])
    return pin.buildReducedModel(model, ids, q)


def _check_home(model: pin.Model, profile: RobotProfile, path: Path) -> None:
    if profile.home is None:
        return
    home = np.array(profile.home, dtype=float)
    if home.shape != (model.nq,) or not np.all(np.isfinite(home)):
        free = [str(model.names[j]) for j in range(1, model.njoints)]
        reason = f"{model.nq} finite joint positions [rad or m], one per free joint ({', '.join(free)})"
        raise _refusal(profile, path, "home", "home", list(profile.home), reason)
    outside = np.flatnonzero((home < model.lowerPositionLimit) | (home > model.upperPositionLimit))
    if outside.size:
        j = int(outside[0])
        reason = (
            f"positions within the joints' ranges; joint {j + 1} ({model.names[j + 1]}) at {home[j]:g} is "
            f"outside [{model.lowerPositionLimit[j]:g}, {model.upperPositionLimit[j]:g}] rad"
        )
        raise _refusal(profile, path, "home", "home", list(profile.home), reason)


def load_robot(
    robot: str | os.PathLike[str] | None = None,
    payload: float = 0.0,
    ee_frame: str | None = None,
    parameter_map: Callable[[pin.Model], ParameterMap] | None = None,
    repair_inertias: bool | None = None,
) -> RobotModel:
    """Load an arm by name or from a URDF file.

    Args:
        robot: A catalog name (``"twolink"``, the default) or a path to a URDF file.
        payload: Point mass at the end-effector frame's origin [kg], >= 0.
        ee_frame: Name of the end-effector frame; default the profile's, else ``ee_link``
            if present, else the last frame on the last joint.
        parameter_map: Parameter-map class (called with the model); default the profile's
            (the twolink's lumped p1..p3), else the model's identifiable base parameters
            (:class:`~twolink_pin.model.base_parameters.BaseParameterMap`).
        repair_inertias: Replace each link inertia that breaks the triangle inequality by the
            nearest one that satisfies it (``RobotModel.repairs`` lists each change) instead of
            refusing the file; default the profile's (``repair_inertias`` of a profile file), else no.

    Raises:
        InvalidURDFError: unknown name, missing file, or a file that gives no sound model.
        InvalidParameterError: ``payload`` is negative or not finite.
    """
    if not (
        isinstance(payload, (int, float))
        and not isinstance(payload, bool)
        and math.isfinite(payload)
        and payload >= 0
    ):
        raise InvalidParameterError("payload", payload, "a finite mass >= 0 kg")
    if robot is not None and not isinstance(robot, (str, os.PathLike)):
        raise InvalidParameterError(
            "robot", type(robot).__name__, "a robot name (twolink-pin robots) or a path to a URDF file"
        )
    path, profile = resolve(robot)
    repair = profile.repair_inertias if repair_inertias is None else bool(repair_inertias)
    checked = check_urdf_file(path, repair)
    model, profile = _build_model(path, profile, checked)
    _check_home(model, profile, path)
    _check_sizes(model, profile, path)
    ee_id = _end_effector_frame(model, ee_frame, path, profile)
    if profile.q0_offset is None:  # never a run that starts on its reference (docs/any_robot.md)
        profile = dataclasses.replace(profile, q0_offset=default_q0_offset(model.nv))
    if payload > 0:
        frame = model.frames[ee_id]
        point = pin.Inertia(float(payload), np.zeros(3), np.zeros((3, 3)))
        model.inertias[frame.parentJoint] = model.inertias[frame.parentJoint] + frame.placement.act(point)
    _check_inertias(model, path, payload)
    _check_moves_inertia(model, path)
    if profile.home is None:  # a dexterous home near the middle of the ranges (model/home.py)
        chosen = choose_home(model, ee_id)
        profile = dataclasses.replace(profile, home=tuple(chosen.q.tolist()), home_source=chosen.describe())
    factory = parameter_map if parameter_map is not None else profile.parameter_map
    pmap: ParameterMap = factory(model) if factory is not None else BaseParameterMap(model)
    return RobotModel(
        model=model,
        urdf_path=path,
        ee_frame_id=ee_id,
        payload=float(payload),
        parameter_map=pmap,
        link_lengths=readonly(_link_lengths(model, ee_id)),
        torque_limits=readonly(np.where(model.effortLimit > 0, model.effortLimit, np.inf)),
        p=readonly(pmap.values(model)),
        profile=profile,
        notes=checked.notes,
        repairs=checked.repairs,
        urdf_text=checked.text,
    )
