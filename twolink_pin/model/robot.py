"""Loading a robot arm from URDF into Pinocchio.

:func:`load_robot` resolves a robot name or a URDF path (:mod:`twolink_pin.model.catalog`),
validates the file (:mod:`twolink_pin.model.urdf_validation`), builds the Pinocchio model,
optionally adds a point-mass payload at the end effector, and reads everything else the
toolkit needs from the model: link lengths, torque limits and the parameters ``p`` of the
robot's parameter map. The robot's :class:`~twolink_pin.model.profile.RobotProfile` rides
along (its gain presets, default trajectory, plant friction).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.model.catalog import example_robot_urdf, resolve
from twolink_pin.model.parameters import InertialParameterMap, ParameterMap
from twolink_pin.model.profile import RobotProfile
from twolink_pin.model.urdf_validation import validate_urdf_file

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

    @property
    def name(self) -> str:
        """The robot's short name (catalog name or URDF file stem)."""
        return self.profile.name

    @property
    def gain_presets(self) -> Mapping[str, Mapping[str, Any]]:
        """Gains per law name that laws built on this robot use by default."""
        return self.profile.gain_presets

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


def _end_effector_frame(model: pin.Model, ee_frame: str | None, path: Path) -> int:
    if ee_frame is not None:
        if not model.existFrame(ee_frame):
            names = [f.name for f in model.frames]
            raise InvalidURDFError(str(path), f"frame '{ee_frame}'", f"no such frame; frames are {names}")
        return int(model.getFrameId(ee_frame))
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


def load_robot(
    robot: str | os.PathLike[str] | None = None,
    payload: float = 0.0,
    ee_frame: str | None = None,
    parameter_map: Callable[[pin.Model], ParameterMap] | None = None,
) -> RobotModel:
    """Load an arm by name or from a URDF file.

    Args:
        robot: A catalog name (``"twolink"``, the default) or a path to a URDF file.
        payload: Point mass at the end-effector frame's origin [kg], >= 0.
        ee_frame: Name of the end-effector frame; default the profile's, else ``ee_link``
            if present, else the last frame on the last joint.
        parameter_map: Parameter-map class (called with the model); default the profile's
            (the twolink's lumped p1..p3), else :class:`InertialParameterMap` (all π).

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
    path, profile = resolve(robot)
    validate_urdf_file(path)
    try:
        model = pin.buildModelFromUrdf(str(path))
    except (ValueError, RuntimeError) as exc:  # validated already; keep any surprise readable
        raise InvalidURDFError(str(path), "<robot>", f"Pinocchio could not build a model: {exc}") from exc
    if model.nv == 0:
        raise InvalidURDFError(str(path), "<robot>", "expected at least one moving joint, found none")
    if model.nq != model.nv:
        raise InvalidURDFError(
            str(path),
            "<robot>",
            f"expected only 1-DoF joints (nq == nv), got nq = {model.nq}, nv = {model.nv}",
        )
    ee_id = _end_effector_frame(model, ee_frame if ee_frame is not None else profile.ee_frame, path)
    if payload > 0:
        frame = model.frames[ee_id]
        point = pin.Inertia(float(payload), np.zeros(3), np.zeros((3, 3)))
        model.inertias[frame.parentJoint] = model.inertias[frame.parentJoint] + frame.placement.act(point)
    _check_inertias(model, path, payload)
    _check_moves_inertia(model, path)
    factory = parameter_map if parameter_map is not None else profile.parameter_map
    pmap: ParameterMap = factory(model) if factory is not None else InertialParameterMap(model)
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
    )
