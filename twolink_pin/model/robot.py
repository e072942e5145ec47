"""Loading a robot arm from URDF into Pinocchio.

:func:`load_robot` validates the file (:mod:`twolink_pin.urdf_validation`), builds the
Pinocchio model, optionally adds a point-mass payload at the end effector, and reads
everything else the toolkit needs from the model: link lengths, torque limits and the
parameters ``p`` of the model's parameter map.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin

from twolink_pin.arrays import readonly
from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.model.parameters import InertialParameterMap, ParameterMap
from twolink_pin.model.urdf_validation import validate_urdf_file
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap

DEFAULT_EE_FRAME = "ee_link"


def twolink_urdf_path() -> Path:
    """Path of the shipped ``twolink.urdf`` (works from a checkout and an installed wheel)."""
    return Path(str(resources.files("twolink_pin.robots").joinpath("twolink.urdf")))


def example_robot_urdf(relative: str) -> Path:
    """Path of a URDF shipped by ``example-robot-data``.

    Args:
        relative: Path below the package's ``robots/`` folder, e.g.
            ``"double_pendulum_description/urdf/double_pendulum.urdf"`` or
            ``"asr_twodof_description/urdf/TwoDofs.urdf"`` (a planar 2-DOF arm).

    Raises:
        InvalidURDFError: the distribution is not installed or has no such file.
    """
    import importlib.metadata

    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        raise InvalidURDFError(
            relative, "example-robot-data", "not installed (pip install example-robot-data)"
        ) from None
    suffix = "robots/" + relative.lstrip("/")
    for file in files:
        if str(file).endswith(suffix):
            return Path(str(file.locate()))
    raise InvalidURDFError(
        relative, "example-robot-data", f"no file ending in {suffix!r} in the installed distribution"
    )


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


def load_robot(
    urdf: str | os.PathLike[str] | None = None,
    payload: float = 0.0,
    ee_frame: str | None = None,
    parameter_map: Callable[[pin.Model], ParameterMap] | None = None,
) -> RobotModel:
    """Load an arm from URDF.

    Args:
        urdf: URDF file; default the shipped ``twolink.urdf``.
        payload: Point mass at the end-effector frame's origin [kg], >= 0.
        ee_frame: Name of the end-effector frame; default ``ee_link`` if present, else the
            last frame on the last joint.
        parameter_map: Parameter-map class (called with the model); default :class:`TwoLinkLumpedMap` for a
            planar 2R arm, else :class:`InertialParameterMap` (all of Pinocchio's π).

    Raises:
        InvalidURDFError: the file is missing or describes no sound model.
        InvalidParameterError: ``payload`` is negative or not finite.
    """
    if not (
        isinstance(payload, (int, float))
        and not isinstance(payload, bool)
        and math.isfinite(payload)
        and payload >= 0
    ):
        raise InvalidParameterError("payload", payload, "a finite mass >= 0 kg")
    path = Path(urdf) if urdf is not None else twolink_urdf_path()
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
    ee_id = _end_effector_frame(model, ee_frame, path)
    if payload > 0:
        frame = model.frames[ee_id]
        point = pin.Inertia(float(payload), np.zeros(3), np.zeros((3, 3)))
        model.inertias[frame.parentJoint] = model.inertias[frame.parentJoint] + frame.placement.act(point)
    if parameter_map is None:
        pmap: ParameterMap = (
            TwoLinkLumpedMap(model) if TwoLinkLumpedMap.applies_to(model) else InertialParameterMap(model)
        )
    else:
        pmap = parameter_map(model)
    return RobotModel(
        model=model,
        urdf_path=path,
        ee_frame_id=ee_id,
        payload=float(payload),
        parameter_map=pmap,
        link_lengths=readonly(_link_lengths(model, ee_id)),
        torque_limits=readonly(np.where(model.effortLimit > 0, model.effortLimit, np.inf)),
        p=readonly(pmap.values(model)),
    )
