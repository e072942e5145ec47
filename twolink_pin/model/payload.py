"""Payload variants as URDF files.

:func:`load_robot` adds a payload inside Pinocchio; this module writes the same variant as
a URDF (a point mass at the origin of the end-effector link, edited with ``yourdfpy``) so it
can be shared, viewed or loaded by other tools. Loading the written file gives the same
inertias as ``load_robot(payload=m)`` (tested for every catalog arm). A link that has an
``<inertial>`` of its own (the UR5's ``tool0``) gets the sum of its body and the point mass
(``pin.Inertia`` addition: mass, centre of mass and inertia about it), which is what
Pinocchio builds from ``load_robot(payload=m)``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.files import atomic_write
from twolink_pin.model.urdf_profile import declare_profile
from twolink_pin.model.urdf_validation import validate_urdf_file

POINT_MASS_INERTIA = 0.0
"""Inertia [kg·m²] of the point mass about its centre: none, as in ``load_robot(payload=m)``
(a URDF inertia of all zeros with a mass > 0 is a point mass)."""


def payload_urdf(urdf: str | os.PathLike[str], payload: float, link: str = "ee_link") -> str:
    """URDF text of ``urdf`` with a point mass ``payload`` [kg] at the origin of ``link``.

    A link with an inertial of its own gets the sum of its body and the point mass.

    Raises:
        InvalidParameterError: ``payload`` not a finite mass > 0 kg.
        InvalidURDFError: the file is invalid, or ``link`` is missing.
    """
    import yourdfpy

    if not (isinstance(payload, (int, float)) and math.isfinite(payload) and payload > 0):
        raise InvalidParameterError("payload", payload, "a finite mass > 0 kg")
    path = Path(urdf)
    validate_urdf_file(path)
    robot = yourdfpy.URDF.load(
        str(path), build_scene_graph=False, load_meshes=False, build_collision_scene_graph=False
    )
    if link not in robot.link_map:
        raise InvalidURDFError(
            str(path), f"link '{link}'", f"no such link; links are {sorted(robot.link_map)}"
        )
    target = robot.link_map[link]
    total = pin.Inertia(float(payload), np.zeros(3), POINT_MASS_INERTIA * np.eye(3))
    own = target.inertial
    if own is not None and own.mass is not None and own.mass > 0:
        origin = np.eye(4) if own.origin is None else np.asarray(own.origin, dtype=float)
        rotation = origin[:3, :3]
        inertia = np.zeros((3, 3)) if own.inertia is None else np.asarray(own.inertia, dtype=float)
        total = total + pin.Inertia(float(own.mass), origin[:3, 3], rotation @ inertia @ rotation.T)
    centre = np.eye(4)
    centre[:3, 3] = total.lever
    target.inertial = yourdfpy.Inertial(
        origin=centre, mass=float(total.mass), inertia=np.array(total.inertia)
    )
    text = robot.write_xml_string()
    return text.decode() if isinstance(text, bytes) else str(text)


def write_payload_urdf(
    urdf: str | os.PathLike[str],
    payload: float,
    out: str | os.PathLike[str],
    link: str = "ee_link",
    profile: str | None = None,
) -> Path:
    """Write :func:`payload_urdf` to ``out`` atomically, declaring the catalog ``profile`` it
    keeps when loaded back (:mod:`~twolink_pin.model.urdf_profile`); returns the path."""
    text = payload_urdf(urdf, payload, link)
    if profile is not None:
        text = declare_profile(text, profile)
    with atomic_write(out) as f:
        f.write(text)
    return Path(out)
