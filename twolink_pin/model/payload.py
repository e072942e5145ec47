"""Payload variants as URDF files.

:func:`load_robot` adds a payload inside Pinocchio; this module writes the same variant as
a URDF (a point mass on the end-effector link, edited with ``yourdfpy``) so it can be
shared, viewed or loaded by other tools. Loading the written file gives the same ``p``
as ``load_robot(payload=m)`` (tested).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.files import atomic_write
from twolink_pin.model.urdf_validation import validate_urdf_file

POINT_MASS_INERTIA = 0.0
"""Inertia [kg·m²] of the point mass about its centre: none, as in ``load_robot(payload=m)``
(a URDF inertia of all zeros with a mass > 0 is a point mass)."""


def payload_urdf(urdf: str | os.PathLike[str], payload: float, link: str = "ee_link") -> str:
    """URDF text of ``urdf`` with a point mass ``payload`` [kg] at the origin of ``link``.

    The link must have no inertial of its own (the twolink's ``ee_link`` has none).

    Raises:
        InvalidParameterError: ``payload`` not a finite mass > 0 kg.
        InvalidURDFError: the file is invalid, or ``link`` is missing or already has mass.
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
    if target.inertial is not None:
        raise InvalidURDFError(
            str(path), f"link '{link}' <inertial>", "expected a massless link to carry the payload"
        )
    target.inertial = yourdfpy.Inertial(
        origin=np.eye(4), mass=float(payload), inertia=POINT_MASS_INERTIA * np.eye(3)
    )
    text = robot.write_xml_string()
    return text.decode() if isinstance(text, bytes) else str(text)


def write_payload_urdf(
    urdf: str | os.PathLike[str], payload: float, out: str | os.PathLike[str], link: str = "ee_link"
) -> Path:
    """Write :func:`payload_urdf` to ``out`` atomically; returns the path."""
    text = payload_urdf(urdf, payload, link)
    with atomic_write(out) as f:
        f.write(text)
    return Path(out)
