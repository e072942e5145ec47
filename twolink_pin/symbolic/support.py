"""Which arms the derivation takes, and the one line that says why it refuses the others.

It derives **fixed-base open chains of revolute and prismatic joints** (continuous joints
are revolute joints without limits, fixed joints are folded into the links they join; a
branching tree is an open chain too), of at most :data:`MAX_JOINTS` moving joints — the
size it derives in the time ``docs/equations.md`` states. It refuses, each with one line
naming the joint or link and the reason (:class:`~twolink_pin.errors.EquationsError`):

* a **floating** joint (a floating base: six coordinates no motor drives);
* a **planar** joint, or any type a URDF does not define (``spherical``, ``ball``, ...);
* a **closed chain** (a link that is the child of two joints, or joints in a loop);
* an arm of more than :data:`MAX_JOINTS` joints (``--joints N`` derives its first N, the
  others held at 0).

:func:`check_urdf` reads the file's joints before the validator and Pinocchio do, so the
reason is said in these terms rather than as a URDF or parser error; :func:`check_model`
checks the model Pinocchio built.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from twolink_pin.errors import EquationsError, InvalidParameterError, TwolinkPinError
from twolink_pin.symbolic.skeleton import SUPPORTED

MAX_JOINTS = 6
"""The most moving joints derived (a 6-joint arm: about a minute on a quiet machine, see
``docs/equations.md``; beyond, the expressions grow past what anyone reads)."""
DERIVED_TYPES = ("revolute", "continuous", "prismatic", "fixed")
"""URDF joint types the derivation takes."""
_REFUSED = {
    "floating": "a floating base (six coordinates no motor drives); the equations are derived for fixed-base "
    "arms: give the arm without its floating joint",
    "planar": "a planar joint (two translations and a rotation in one joint); the equations are derived for "
    "revolute, continuous and prismatic joints: write it as two prismatic joints and a revolute one",
}
EXPECTED = "revolute, continuous or prismatic (fixed joints are folded into their links)"


def _joint_reason(name: str, kind: str) -> str:
    reason = _REFUSED.get(kind)
    if reason is None:
        reason = f"not a joint the equations derive: expected {EXPECTED}"
    return f"joint '{name}' is {kind}: {reason}"


def check_urdf(path: str | os.PathLike[str]) -> None:
    """Refuse a URDF whose joints the derivation does not take (module docstring). A file that
    cannot be read or parsed passes: the URDF validator then says why.

    Raises:
        EquationsError: a floating, planar or unknown joint type, or a closed chain.
    """
    from twolink_pin.files import read_input_file
    from twolink_pin.model.urdf_validation import MAX_URDF_BYTES

    try:  # never blocks on a FIFO or a device: refused unread, and the validator says why
        text = read_input_file(path, MAX_URDF_BYTES, "a URDF file")
    except TwolinkPinError:
        return
    if b"<!DOCTYPE" in text or b"<!ENTITY" in text:
        return  # the validator refuses these before any expansion
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return
    robot = str(path)
    parent_of: dict[str, str] = {}
    for joint in root.findall("joint"):  # direct children: a <transmission> has <joint> elements too
        name, kind = str(joint.get("name")), str(joint.get("type"))
        if kind not in DERIVED_TYPES:
            raise EquationsError(robot, _joint_reason(name, kind))
        child = joint.find("child")
        link = None if child is None else child.get("link")
        if link is None:
            continue
        if link in parent_of:
            raise EquationsError(
                robot,
                f"link '{link}' is the child of joints '{parent_of[link]}' and '{name}': a closed chain; the "
                "equations are derived for open chains (each link the child of one joint)",
            )
        parent_of[link] = name
    links = {str(link.get("name")) for link in root.findall("link")}
    if links and all(link in parent_of for link in links):
        raise EquationsError(
            robot,
            "every link is the child of a joint: the joints close a loop (a closed chain); expected an open chain",
        )


def check_model(model: pin.Model, robot: str) -> None:
    """Refuse a model the derivation does not take: a joint kind it does not handle, or more
    than :data:`MAX_JOINTS` joints.

    Raises:
        EquationsError: naming the joint or the number of joints.
    """
    for j in range(1, model.njoints):
        kind = model.joints[j].shortname()
        if kind not in SUPPORTED:
            readable = kind.removeprefix("JointModel")
            raise EquationsError(robot, _joint_reason(str(model.names[j]), readable))
    if model.nv > MAX_JOINTS:
        raise EquationsError(
            robot,
            f"has {model.nv} moving joints: the equations are derived for arms of at most {MAX_JOINTS} "
            "(docs/equations.md: time and size per number of joints); derive its first joints with --joints N",
        )


def first_joints(model: pin.Model, count: int) -> pin.Model:
    """``model`` with only its first ``count`` moving joints: the others locked at 0 (clipped
    into their limits), their links riding on the link before them (``pin.buildReducedModel``).

    Raises:
        InvalidParameterError: ``count`` is not between 1 and the model's number of joints.
    """
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= model.nv:
        raise InvalidParameterError(
            "joints", count, f"a whole number from 1 to {model.nv} (the arm's joints)"
        )
    if count == model.nv:
        return model
    q = np.clip(pin.neutral(model), model.lowerPositionLimit, model.upperPositionLimit)
    locked = [j for j in range(1, model.njoints) if model.idx_vs[j] >= count]
    return pin.buildReducedModel(model, locked, q)
