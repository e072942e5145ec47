"""Whether a contact can be integrated at the run's step: the stiffness RK4 can take, and the
contact's stiffness as the joints see it.

Pressed against a surface of stiffness k [N/m] and damping b [N·s/m], the contact point moves
along the normal as a mass–spring–damper ``m ẍ + b ẋ + k x = 0`` whose mass is the arm's
**effective mass along the normal** ``m = 1 / (nᵀ J M⁻¹ Jᵀ n)`` [kg] (``J`` the linear rows of the
contact point's world-aligned Jacobian). Classical RK4 at a step ``h`` is stable for that
motion when both eigenvalues ``s`` of ``m s² + b s + k`` have ``|R(s h)| <= 1`` with
``R(z) = 1 + z + z²/2 + z³/6 + z⁴/24`` (the method's stability function); without damping this
is ``h sqrt(k/m) <= 2√2``. :func:`largest_stable_stiffness` solves for k, :func:`largest_stable_step`
for h. The Pinocchio plant checks a contact when it starts
(:class:`~twolink_pin.contact.compliant.CompliantContact`) and fails the run at that time with
these numbers rather than letting it blow up.

:func:`joint_stiffness` gives the same contact as the joints see it,
``K_q = Σ k_s Jᵀ n_s n_sᵀ J`` [N·m/rad] and ``B_q = Σ b_s Jᵀ n_s n_sᵀ J`` [N·m·s/rad] at a
configuration: the term a pre-run check of the step against the plant's stiffest linear terms
(gains, joint damping, contact) adds for a scene.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.contact.scene import Scene
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def rk4_amplification(z: complex | np.ndarray) -> np.ndarray:
    """``|R(z)|`` of classical RK4 (its stability function), for complex ``z = s h``."""
    z = np.asarray(z, dtype=complex)
    return np.abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)


def _stable(mass: float, damping: float, stiffness: float, step: float) -> bool:
    roots = np.roots([mass, damping, stiffness])
    return bool(np.all(rk4_amplification(roots * step) <= 1.0 + 1e-12))


def largest_stable_stiffness(mass: float, damping: float, step: float) -> float:
    """The largest k [N/m] whose contact RK4 integrates stably at ``step`` [s] for an effective
    mass ``mass`` [kg] and damping ``damping`` [N·s/m] (0 when the damping alone is beyond the
    step: ``b h / m`` past RK4's real-axis limit 2.785)."""
    if not (mass > 0 and step > 0 and damping >= 0):
        raise InvalidParameterError("mass, step", (mass, step), "a mass > 0 kg and a step > 0 s")
    if not _stable(mass, damping, 1e-300, step):
        return 0.0
    high = mass * (3.0 / step) ** 2 + damping * 3.0 / step  # past the imaginary-axis limit 2√2
    while _stable(mass, damping, high, step):
        high *= 4.0
    low = 0.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if _stable(mass, damping, middle, step):
            low = middle
        else:
            high = middle
        if high - low <= 1e-12 * high:
            break
    return low


def largest_stable_step(mass: float, damping: float, stiffness: float) -> float:
    """The largest RK4 step [s] that integrates the contact of ``stiffness`` [N/m], ``damping``
    [N·s/m] on ``mass`` [kg] stably."""
    roots = np.roots([mass, damping, stiffness])
    scale = float(np.max(np.abs(roots)))
    low, high = 0.0, 4.0 / scale
    for _ in range(200):
        middle = 0.5 * (low + high)
        if np.all(rk4_amplification(roots * middle) <= 1.0 + 1e-12):
            low = middle
        else:
            high = middle
        if high - low <= 1e-12 * high:
            break
    return low


def effective_mass(
    model: pin.Model, data: pin.Data, q: np.ndarray, jacobian: np.ndarray, normal: np.ndarray
) -> float:
    """``1 / (nᵀ J M⁻¹ Jᵀ n)`` [kg]: the arm's inertia along the unit ``normal`` at the contact
    point whose linear Jacobian rows are ``jacobian`` (3, nv), at ``q``."""
    Minv = pin.computeMinverse(model, data, q)
    Minv = np.triu(Minv) + np.triu(Minv, 1).T
    row = normal @ jacobian
    inverse = float(row @ Minv @ row)
    return math.inf if inverse <= 0 else 1.0 / inverse


def too_stiff(mass: float, stiffness: float, damping: float, step: float) -> str | None:
    """Why a contact of ``stiffness`` [N/m], ``damping`` [N·s/m] on an effective ``mass`` [kg]
    cannot be integrated at ``step`` [s] (None: it can): the largest stable stiffness for the
    step and the largest stable step for the stiffness."""
    if not math.isfinite(mass) or _stable(mass, damping, stiffness, step):
        return None
    k_max = largest_stable_stiffness(mass, damping, step)
    h_max = largest_stable_step(mass, damping, stiffness)
    what = (
        f"stiffness {stiffness:.4g} N/m > {k_max:.4g} N/m, the largest stable stiffness at --dt {step:g} s"
        if k_max > 0
        else f"damping {damping:.4g} N·s/m is beyond what --dt {step:g} s can integrate at any stiffness"
    )
    return (
        f"the contact is too stiff for the step: {what} (RK4, effective mass {mass:.4g} kg along the "
        f"normal, damping {damping:.4g} N·s/m); use --dt {h_max:.3g} s or less, or a softer surface"
    )


class JointStiffness(NamedTuple):
    """A scene's contact as the joints see it at one configuration."""

    stiffness: np.ndarray
    """``K_q = Σ k_s Jᵀ n_s n_sᵀ J`` [N·m/rad], symmetric, shape (nv, nv)."""
    damping: np.ndarray
    """``B_q = Σ b_s Jᵀ n_s n_sᵀ J`` [N·m·s/rad], shape (nv, nv)."""


def contact_frame(robot: RobotModel, scene: Scene) -> int:
    """The id of the scene's touching frame on ``robot`` (its end effector by default).

    Raises:
        InvalidParameterError: no such frame (the message lists some).
    """
    if scene.frame is None:
        return int(robot.ee_frame_id)
    if not robot.model.existFrame(scene.frame):
        names = [f.name for f in robot.model.frames][:12]
        raise InvalidParameterError(
            "scene.frame", scene.frame, f"a frame of {robot.name}, e.g. {', '.join(names)}"
        )
    return int(robot.model.getFrameId(scene.frame))


def joint_stiffness(robot: RobotModel, scene: Scene, q: np.ndarray) -> JointStiffness:
    """Every surface of ``scene`` as the joints would feel it touching at ``q`` [rad] (whether
    or not the arm touches there): the linearised contact's stiffness and damping in joint space
    (see the module docstring). With the mass matrix ``M(q)``, the largest eigenvalue of
    ``M⁻¹ K_q`` is the square of the contact's fastest angular frequency [rad²/s²]."""
    model = robot.model
    data = model.createData()
    q = np.asarray(q, dtype=float)
    J = pin.computeFrameJacobian(model, data, q, contact_frame(robot, scene), WORLD_ALIGNED)[:3]
    K = np.zeros((robot.nv, robot.nv))
    B = np.zeros((robot.nv, robot.nv))
    for surface in scene.surfaces:
        row = surface.unit_normal @ J
        K += surface.stiffness * np.outer(row, row)
        B += surface.damping * np.outer(row, row)
    return JointStiffness(K, B)


__all__ = [
    "JointStiffness",
    "contact_frame",
    "effective_mass",
    "joint_stiffness",
    "largest_stable_step",
    "largest_stable_stiffness",
    "rk4_amplification",
    "too_stiff",
]
