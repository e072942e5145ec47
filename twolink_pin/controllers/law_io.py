"""What flows through a law's one method: :class:`LawInput` (time, state, reference, the
contact's reading, the reference ahead) in, :class:`LawOutput` (τ, ż) out, and :class:`Terms`,
the Pinocchio quantities the engine evaluates for the law's N runs (:class:`FrameTerms` for a
frame). The law's class itself (:class:`~twolink_pin.controllers.base.Controller`) is in
:mod:`twolink_pin.controllers.base`."""

from __future__ import annotations

from typing import Any, NamedTuple, Protocol

import numpy as np

from twolink_pin.controllers.contact_input import ContactInput
from twolink_pin.controllers.preview import ReferencePreview


class LawInput(NamedTuple):
    """What a law sees at one evaluation, for N runs (arrays batch-first)."""

    t: float
    """Simulated time [s] (the same for every run)."""
    q: np.ndarray
    """Joint positions [rad], shape (N, nv)."""
    v: np.ndarray
    """Joint velocities [rad/s], shape (N, nv)."""
    z: np.ndarray
    """The law's internal state (e.g. parameter estimates), shape (N, nz); nz may be 0."""
    q_des: np.ndarray
    """Reference position [rad], shape (1, nv)."""
    v_des: np.ndarray
    """Reference velocity [rad/s], shape (1, nv)."""
    a_des: np.ndarray
    """Reference acceleration [rad/s²], shape (1, nv)."""
    x_des: np.ndarray | None = None
    """Desired end-effector position [m], shape (1, 3): the SE(3) reference's
    (:class:`~twolink_pin.trajectory.se3.PoseTrajectory`), else the forward kinematics of
    the joint reference. Filled for a law that declares ``task_space = True``, else None."""
    R_des: np.ndarray | None = None
    """Desired end-effector orientation (its axes in world coordinates), shape (1, 3, 3)."""
    twist_des: np.ndarray | None = None
    """Desired twist ``[ṗ; ω]`` [m/s; rad/s], world-aligned, linear rows first, shape (1, 6)."""
    accel_des: np.ndarray | None = None
    """Desired spatial (classical) acceleration ``[p̈; ω̇]`` [m/s²; rad/s²], world-aligned,
    linear rows first, shape (1, 6)."""
    contact: ContactInput | None = None
    """The force sensor's wrench, the force reference and its surface's normal
    (:class:`~twolink_pin.controllers.contact_input.ContactInput`) when the plant's scene has
    surfaces (``--scene``, ``--wall``), else None."""
    preview: ReferencePreview | None = None
    """The reference ahead of now at the offsets the law declares
    (:meth:`Controller.preview_times`): times (P,) and ``q``, ``q̇``, ``q̈`` of shape (1, P, nv)
    (:class:`~twolink_pin.controllers.preview.ReferencePreview`); None for a law that
    declares none."""


class LawOutput(NamedTuple):
    """What a law returns: the torque and, for a law with state, the state's derivative."""

    tau: np.ndarray
    """Commanded joint torque [N·m], shape (N, nv)."""
    dz: np.ndarray | None = None
    """``ż``, shape (N, nz); ``None`` for a law without state."""


class FrameTerms(NamedTuple):
    """A frame's pose and first-order kinematics for N runs (:meth:`Terms.frame`).

    Convention: Pinocchio's ``LOCAL_WORLD_ALIGNED`` — velocities of the frame's origin,
    expressed in the world's axes; in every 6-vector the linear part comes first
    (``[v; ω]``, ``[a; α]``).
    """

    position: np.ndarray
    """The frame's origin in the world [m], shape (N, 3)."""
    rotation: np.ndarray
    """The frame's orientation (its axes in world coordinates), shape (N, 3, 3)."""
    jacobian: np.ndarray
    """``J`` with ``[ṗ; ω] = J q̇`` [m/rad; 1], shape (N, 6, nv)."""
    drift: np.ndarray
    """``J̇ q̇`` [m/s²; rad/s²], shape (N, 6): the frame's classical acceleration at
    ``q̈ = 0``, so that ``[p̈; ω̇] = J q̈ + J̇ q̇``."""


class Terms(Protocol):
    """The Pinocchio quantities a law may ask for, evaluated by the engine for all N runs.

    Arguments broadcast: each is ``(N, nv)`` or ``(1, nv)``. Implementations live in
    :mod:`twolink_pin.simulation.terms` (:func:`~twolink_pin.simulation.terms.terms_for`
    builds the one the engine would use, e.g. to test a law by itself).
    """

    def model(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``M̂(q) a + Ĉ(q, v) w + ĝ(q)`` [N·m], shape (N, nv), on the controller's model
        (its robot, or its ``model_parameters``); ``C`` is the Christoffel form."""
        ...

    def regressor(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``Y`` with ``Y p = M(q) a + C(q, v) w + g(q)`` for the robot's parameter map
        (whatever the inertias), shape (N, nv, n_p)."""
        ...

    def friction_regressor(self, v: np.ndarray, smoothing: float = 0.0) -> np.ndarray:
        """``[diag(q̇), diag(sgn q̇)]`` per run, shape (N, nv, 2 nv): ``f(q̇) = Y_f (V, C)``;
        ``tanh(q̇/smoothing)`` for the sign when ``smoothing > 0`` [rad/s]."""
        ...

    def mass(self, q: np.ndarray) -> np.ndarray:
        """``M̂(q)`` [kg·m² for revolute joints], symmetric, shape (N, nv, nv), on the
        controller's model (Pinocchio's CRBA)."""
        ...

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """``ĝ(q)`` [N·m], shape (N, nv), on the controller's model."""
        ...

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``Ĉ(q, q̇) q̇ + ĝ(q)`` [N·m], shape (N, nv), on the controller's model
        (Pinocchio's ``nonLinearEffects``)."""
        ...

    def solve_mass(self, q: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``M̂(q)⁻¹ b``, shape (N, nv) for ``b`` of shape (N, nv) or (N, nv, k) for
        (N, nv, k): a linear solve on ``M̂`` (LU), never an explicit inverse."""
        ...

    def inverse_dynamics_derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Any:
        """``τ = M̂ a + Ĉ(q, v) v + ĝ`` and its derivatives ``∂τ/∂q``, ``∂τ/∂v`` and
        ``∂τ/∂a = M̂`` at K states of each run, on the controller's model (Pinocchio's
        ``computeRNEADerivatives``): arguments of shape (N, K, nv) (row i: run i's states),
        a :class:`~twolink_pin.dynamics.InverseDynamicsDerivatives` of shapes (N, K, nv) and
        (N, K, nv, nv). What a law that plans (:meth:`Controller.update`) linearises with."""
        ...

    def frame(self, q: np.ndarray, v: np.ndarray, frame: str | None = None) -> FrameTerms:
        """Pose, Jacobian and ``J̇ q̇`` of ``frame`` (default: the robot's end effector),
        ``LOCAL_WORLD_ALIGNED``, linear rows first (see :class:`FrameTerms`). Pure
        kinematics: the same on every model of the robot. A ``(1, nv)`` argument gives
        ``(1, …)`` results (e.g. the reference's frame)."""
        ...
