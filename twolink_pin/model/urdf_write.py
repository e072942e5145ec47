"""A robot's URDF with other inertial parameters (and joint friction) written in.

``identify --write-urdf OUT.urdf`` takes the user's URDF and replaces, for each moving body,
the ``<inertial>`` of the link its joint moves by the identified one: Pinocchio's ten
parameters of a body ``π = (m, m c, I_o)`` (``I_o`` about the joint frame's origin) become
URDF's mass, centre of mass ``c`` (``<origin xyz>``, in the link frame, which URDF makes the
joint frame) and inertia about the centre of mass ``I_c = I_o − m (|c|² 𝟙 − c cᵀ)``
(``pin.Inertia.FromDynamicParameters``). Links fixed to that link (Pinocchio merged them into
the body) lose their ``<inertial>``: the body's parameters are the sum. Numbers are written
with 17 significant digits, so the model read back has the same parameters to rounding.

Friction, when given, goes into each moving joint's ``<dynamics damping="V" friction="C">``
[N·m·s/rad, N·m] (URDF's viscous and Coulomb coefficients; Pinocchio reads them into
``model.damping`` / ``model.friction``, :func:`joint_friction` reads them back). Everything
else of the file (comments, visuals, limits) is kept as it was.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model.parameters import N_BODY_PARAMETERS


def _number(x: float) -> str:
    return repr(float(x))


def _fixed_descendants(root: ET.Element, link: str) -> list[str]:
    """Links attached to ``link`` through fixed joints only (Pinocchio merges them into its body)."""
    out, frontier = [], [link]
    while frontier:
        parent = frontier.pop()
        for joint in root.findall("joint"):
            if joint.get("type") == "fixed" and joint.find("parent").get("link") == parent:  # type: ignore[union-attr]
                child = joint.find("child").get("link")  # type: ignore[union-attr]
                out.append(str(child))
                frontier.append(str(child))
    return out


def urdf_with_inertias(
    urdf_text: str,
    model: pin.Model,
    standard: np.ndarray,
    friction: tuple[np.ndarray, np.ndarray] | None = None,
) -> str:
    """The URDF ``urdf_text`` with the standard parameters ``standard`` (10 per moving body of
    ``model``, Pinocchio's order) and optionally joint friction ``(V, C)`` written in.

    Raises:
        InvalidParameterError: a body's parameters are not a physical body with positive mass
            (the message names the link), or the model's joints are not the URDF's (a model
            with locked joints).
    """
    root = ET.fromstring(urdf_text)
    joints = {j.get("name"): j for j in root.findall("joint")}
    links = {link.get("name"): link for link in root.findall("link")}
    standard = np.asarray(standard, dtype=float)
    for j in range(1, model.njoints):
        name = str(model.names[j])
        joint = joints.get(name)
        if joint is None or joint.get("type") == "fixed":
            raise InvalidParameterError(
                "urdf", name, "a model whose moving joints are the URDF's (no locked joints)"
            )
        child = str(joint.find("child").get("link"))  # type: ignore[union-attr]
        pi = standard[N_BODY_PARAMETERS * (j - 1) : N_BODY_PARAMETERS * j]
        if not pi[0] > 0:
            raise InvalidParameterError(f"link '{child}' mass", float(pi[0]), "a positive mass [kg]")
        inertia = pin.Inertia.FromDynamicParameters(pi)
        c, rot = np.asarray(inertia.lever), np.asarray(inertia.inertia)
        if not np.linalg.eigvalsh(0.5 * (rot + rot.T))[0] > 0:
            raise InvalidParameterError(
                f"link '{child}' inertia", rot.round(9).tolist(), "positive definite about the centre of mass"
            )
        for other in [child, *_fixed_descendants(root, child)]:
            element = links[other]
            for old in element.findall("inertial"):
                element.remove(old)
        inertial = ET.Element("inertial")
        ET.SubElement(inertial, "origin", xyz=" ".join(_number(x) for x in c), rpy="0 0 0")
        ET.SubElement(inertial, "mass", value=_number(inertia.mass))
        ET.SubElement(
            inertial,
            "inertia",
            ixx=_number(rot[0, 0]),
            ixy=_number(rot[0, 1]),
            ixz=_number(rot[0, 2]),
            iyy=_number(rot[1, 1]),
            iyz=_number(rot[1, 2]),
            izz=_number(rot[2, 2]),
        )
        links[child].insert(0, inertial)
        if friction is not None:
            for old in joint.findall("dynamics"):
                joint.remove(old)
            ET.SubElement(
                joint, "dynamics", damping=_number(friction[0][j - 1]), friction=_number(friction[1][j - 1])
            )
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def joint_friction(path: str | os.PathLike[str], joint_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """``(V, C)`` of the joints ``joint_names`` from their ``<dynamics damping friction>`` (0
    where absent)."""
    root = ET.parse(Path(os.fspath(path))).getroot()
    joints = {j.get("name"): j for j in root.findall("joint")}
    viscous, coulomb = np.zeros(len(joint_names)), np.zeros(len(joint_names))
    for k, name in enumerate(joint_names):
        dynamics = joints[name].find("dynamics") if name in joints else None
        if dynamics is not None:
            viscous[k] = float(dynamics.get("damping", "0"))
            coulomb[k] = float(dynamics.get("friction", "0"))
    return viscous, coulomb
