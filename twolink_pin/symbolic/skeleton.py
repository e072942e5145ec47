"""The arm's kinematic tree as exact data: what the derivation reads from a Pinocchio model.

Pinocchio's URDF parser has already folded every fixed joint into the placements of the
moving ones (``model.jointPlacements``) and the links' inertias into the bodies they ride
on, so the tree to derive is: for each moving joint j, its parent joint, its kind
(revolute or prismatic), its axis in its own frame, and the placement of its frame in its
parent's frame (a rotation and a translation [m]).

Numbers become exact rationals, so that the algebra is exact:

* rotation entries, axes and the gravity direction within :data:`SNAP` of 0 or ±1 are
  those integers (a URDF's ``rpy="0 1.57079632679 0"`` gives ``cos = 4.9e-12``: the author's
  quarter turn), others the nearest fraction of denominator ≤ 10¹² (error ≤ 1e-12);
* each translation component larger than :data:`ZERO_LENGTH` is a **length symbol**
  ``l{j}{x|y|z}`` — joint j's origin along that axis of its parent's frame — with its value
  kept beside it (the twolink's ``l2x`` is the course's L1 = 0.38 m); smaller ones are 0.

:meth:`Skeleton.key` is a digest of all of it: the cache of derivations
(:mod:`~twolink_pin.symbolic.cache`) is keyed on it, so two URDFs with the same kinematics
share a derivation, whatever their inertias or payload (those only give numbers).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import pinocchio as pin

from twolink_pin.model.base_parameters import body_name
from twolink_pin.symbolic.trig_ring import PRISMATIC, REVOLUTE

SNAP = 1e-11
"""A rotation entry, axis or gravity component within this of 0 or ±1 is that integer."""
ZERO_LENGTH = 1e-12
"""A placement offset at most this [m] (a picometre) is exactly 0."""
MAX_DENOMINATOR = 10**12
"""Other numbers are the nearest fraction with at most this denominator."""

_AXES = {"X": (1, 0, 0), "Y": (0, 1, 0), "Z": (0, 0, 1)}
SUPPORTED = {
    **{f"JointModelR{a}": REVOLUTE for a in "XYZ"},
    "JointModelRevoluteUnaligned": REVOLUTE,
    **{f"JointModelP{a}": PRISMATIC for a in "XYZ"},
    "JointModelPrismaticUnaligned": PRISMATIC,
}
"""Pinocchio joint models the derivation handles, and their kind."""


def exact(x: float) -> Fraction:
    """``x`` as an exact rational (see the module docstring)."""
    for whole in (0, 1, -1):
        if abs(x - whole) <= SNAP:
            return Fraction(whole)
    return Fraction(float(x)).limit_denominator(MAX_DENOMINATOR)


@dataclass(frozen=True)
class JointSkeleton:
    """One moving joint of the tree."""

    name: str
    """The joint's name in the URDF."""
    body: str
    """The link it moves (its first body frame)."""
    kind: str
    """:data:`~twolink_pin.symbolic.trig_ring.REVOLUTE` or ``PRISMATIC``."""
    parent: int
    """0-based index of the parent joint, −1 for the base."""
    axis: tuple[Fraction, Fraction, Fraction]
    """Unit axis in the joint's own frame."""
    rotation: tuple[tuple[Fraction, ...], ...]
    """Rotation of the joint frame in the parent's frame (row-major 3 × 3)."""
    offset: tuple[float, float, float]
    """Translation of the joint frame in the parent's frame [m]."""

    def length_names(self, index: int) -> tuple[str | None, str | None, str | None]:
        """The length symbol of each nonzero offset component (``l{index}{x|y|z}``, index 1-based)."""
        return tuple(  # type: ignore[return-value]
            f"l{index}{axis}" if abs(value) > ZERO_LENGTH else None for axis, value in zip("xyz", self.offset)
        )


@dataclass(frozen=True)
class Skeleton:
    """The arm's tree: its joints in Pinocchio's order, and gravity."""

    joints: tuple[JointSkeleton, ...]
    gravity: float
    """|g| [m/s²]."""
    gravity_direction: tuple[Fraction, Fraction, Fraction]
    """Unit direction of gravity in the base frame (``(0, 0, −1)`` for Pinocchio's default)."""

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def tilted(self) -> bool:
        """Whether some rotation entry, axis or gravity component is not 0 or ±1 (an inexact
        constant: :mod:`~twolink_pin.symbolic.trig_ring`, tilted arms)."""
        numbers = [x for j in self.joints for x in (*j.axis, *(y for row in j.rotation for y in row))]
        return any(x not in (0, 1, -1) for x in (*numbers, *self.gravity_direction))

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(j.kind for j in self.joints)

    def lengths(self) -> dict[str, float]:
        """Every length symbol's name and value [m], in joint order."""
        out = {}
        for i, joint in enumerate(self.joints, start=1):
            for name, value in zip(joint.length_names(i), joint.offset):
                if name is not None:
                    out[name] = float(value)
        return out

    def length_meanings(self) -> dict[str, str]:
        """What each length symbol is, in words."""
        out = {}
        for i, joint in enumerate(self.joints, start=1):
            parent = "the base" if joint.parent < 0 else f"joint '{self.joints[joint.parent].name}'"
            for name, axis in zip(joint.length_names(i), "xyz"):
                if name is not None:
                    out[name] = f"origin of joint '{joint.name}' along {axis} of the frame of {parent}"
        return out

    def key(self) -> str:
        """SHA-256 of everything the derivation reads (the cache's key)."""
        text = json.dumps(
            {
                "joints": [
                    [
                        j.kind,
                        j.parent,
                        [str(a) for a in j.axis],
                        [[str(x) for x in r] for r in j.rotation],
                        [name is not None for name in j.length_names(i)],
                    ]
                    for i, j in enumerate(self.joints, start=1)
                ],
                "gravity": [str(x) for x in self.gravity_direction],
            },
            sort_keys=True,
        )
        return hashlib.sha256(text.encode()).hexdigest()


def _axis(model: pin.Model, data: pin.Data, j: int) -> tuple[Fraction, Fraction, Fraction]:
    """Joint j's unit axis in its frame, from its motion subspace (``S``, 6 × 1)."""
    subspace = np.asarray(data.joints[j].S, dtype=float).reshape(6)
    shortname = model.joints[j].shortname()
    vector = subspace[3:] if SUPPORTED[shortname] == REVOLUTE else subspace[:3]
    vector = vector / np.linalg.norm(vector)
    return tuple(exact(x) for x in vector)  # type: ignore[return-value]


def skeleton_of(model: pin.Model) -> Skeleton:
    """The :class:`Skeleton` of ``model`` (joints the derivation handles: :data:`SUPPORTED`;
    :func:`~twolink_pin.symbolic.support.check_model` says which are not, first)."""
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    joints = []
    for j in range(1, model.njoints):
        placement = model.jointPlacements[j]
        joints.append(
            JointSkeleton(
                name=str(model.names[j]),
                body=body_name(model, j),
                kind=SUPPORTED[model.joints[j].shortname()],
                parent=int(model.parents[j]) - 1,
                axis=_axis(model, data, j),
                rotation=tuple(tuple(exact(x) for x in row) for row in placement.rotation),
                offset=tuple(float(x) for x in placement.translation),  # type: ignore[arg-type]
            )
        )
    gravity = np.asarray(model.gravity.linear, dtype=float)
    magnitude = float(np.linalg.norm(gravity))
    direction = gravity / magnitude if magnitude > 0 else np.array([0.0, 0.0, -1.0])
    return Skeleton(
        joints=tuple(joints),
        gravity=magnitude,
        gravity_direction=tuple(exact(x) for x in direction),  # type: ignore[arg-type]
    )
