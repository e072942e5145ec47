r"""The Pinocchio plant's contact: a compliant spring–damper normal force with regularised
Coulomb friction, for N runs at once.

For each surface s (:mod:`twolink_pin.contact.scene`) and each run, at the state ``(q, q̇)``:
the contact sphere of radius r at the touching frame's origin ``p`` has signed distance
``d = n·(p − x_s) − r`` to the plane, penetration ``δ = −d`` and penetration rate
``δ̇ = −n·ṗ``; while it is over the face (:meth:`~twolink_pin.contact.scene.Surface.over_face`)
and ``δ > 0`` the surface pushes the arm at the sphere's contact point ``c = p − r n`` with

$$f = \lambda\,n - \mu \lambda \frac{v_t}{\sqrt{|v_t|^2 + \varepsilon^2}}, \qquad
\lambda = \max(0,\ k\,\delta + b\,\dot\delta)$$

(Kelvin–Voigt, clipped at zero so that a surface never pulls; Hunt and Crossley, *J. Appl.
Mech.* 42(2), 1975, discuss the clip; ``v_t`` the contact point's slip velocity
``ṗ + ω × (c − p)`` without its normal part, ε the scene's ``slip_velocity``). ``|f_t| < μ λ``
always: the regularised friction stays inside Coulomb's cone, and below ε it acts as a steep
viscous friction instead of sticking. The wrench on the arm about the frame's origin,
``[f; (c − p) × f]``, enters ABA as the joint torque ``Jᵀ [f; m]`` (``J`` the frame's
world-aligned Jacobian): :attr:`ContactForces.tau`.

**Why this model and not Pinocchio 4's constraints.** Pinocchio 4 solves rigid (or
proximally compliant) contacts as constraints: ``PointContactConstraintModel`` with the
``ADMMConstraintSolver`` (or ``PGSConstraintSolver``) finds the contact impulses of a time step
from the Delassus matrix — a velocity-level time-stepping scheme with an impact law, one
solve per step. Our engine integrates by fixed-step RK4 with the law at every stage and runs N
runs per call; a force that is a function of the state fits it as is (a batch stays equal to its
single runs), while a constraint solve does not (no stages, impulses at impacts, warm starts per
run). It also matches the experiment taught: the course lab's wall *is* a spring (1000 N/m), a
force sensor reads the spring's force, and MuJoCo's soft contacts model the same penetration.
What this model leaves out: rigid contact (the penetration is real, ``λ/k``), static friction
(below ε the contact creeps), rolling resistance and torsional friction, impacts as
impulses (an impact is a stiff, damped spring over a few steps: the step must resolve it — checked,
:mod:`twolink_pin.contact.stability`), and every link but the touching frame's sphere.

The force sensor reads :attr:`ContactForces.wrench`: the wrench the contact point applies *to the
surfaces* (minus the wrench on the arm), world axes, about the frame's origin — what a wrist
force/torque sensor beyond which only the tip touches measures, and the ``F_tip`` of Lynch and
Park, *Modern Robotics* §11.5.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.contact.scene import Scene, Surface
from twolink_pin.contact.stability import contact_frame, effective_mass, too_stiff
from twolink_pin.errors import ContactError
from twolink_pin.model import RobotModel

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


class ContactForces(NamedTuple):
    """The contact of N runs at one state."""

    wrench: np.ndarray
    """The wrench the contact point applies to the surfaces [N; N·m], world axes, about the
    touching frame's origin, linear rows first: shape (N, 6) (zeros out of contact)."""
    tau: np.ndarray
    """The joint torque the contact adds to the arm, ``−Jᵀ wrench`` [N·m], shape (N, nv)."""
    penetration: np.ndarray
    """The deepest penetration into any surface [m], shape (N,) (0 out of contact)."""


class CompliantContact:
    """The contact of ``scene`` on ``robot`` for ``runs`` runs (see the module docstring).

    Args:
        robot: The arm (its kinematics: any payload leaves them unchanged).
        scene: The surfaces.
        runs: N.
        step: The run's step [s]: a contact that starts too stiff for it fails the run
            (:class:`~twolink_pin.errors.ContactError`); None: no check.

    Calling it with ``(q, q̇)`` (N, nv) gives :class:`ContactForces` (read-only arrays); the last
    result is kept for the same arrays (the law's sensor and the plant's acceleration ask at the
    same stage state).
    Set :attr:`time` [s] before a step: the time a failure names.
    """

    def __init__(self, robot: RobotModel, scene: Scene, runs: int, step: float | None = None) -> None:
        self.scene = scene
        self._model = robot.model
        self._data = robot.model.createData()
        self._frame = contact_frame(robot, scene)
        self._origin = self._data.oMf[self._frame]  # a view of the frame's placement in the Data
        self._runs = runs
        self._step = step
        surfaces = scene.surfaces
        self._normals = np.array([s.normal for s in surfaces])  # (S, 3)
        self._offsets = np.array([s.unit_normal @ np.array(s.point) for s in surfaces]) + scene.radius  # (S,)
        self._bounded = any(s.size is not None for s in surfaces)
        # per surface, as Python floats: (n_x, n_y, n_z, n·x + r, k, b, μ, the face if bounded)
        self._surfaces: list[tuple[float, float, float, float, float, float, float, Face | None]] = [
            (s.normal[0], s.normal[1], s.normal[2], float(s.unit_normal @ np.array(s.point)) + scene.radius,
             s.stiffness, s.damping, s.friction, _face(s))
            for s in surfaces
        ]  # fmt: skip
        self._eps2 = scene.slip_velocity**2
        self._radius = scene.radius
        self._touching: set[tuple[int, int]] = set()  # (run, surface) in contact at the last call
        self._checked: set[tuple[int, int]] = set()  # (run, surface) whose contact's step was checked
        self._last: tuple[np.ndarray, np.ndarray, ContactForces] | None = None
        self._free = ContactForces(np.zeros((runs, 6)), np.zeros((runs, robot.nv)), np.zeros(runs))
        for array in self._free:
            array.setflags(write=False)
        self._zero_row = (np.zeros(6), np.zeros(robot.nv), 0.0)
        self.time = 0.0
        """The simulated time [s] of the step under way (set by the caller)."""

    @property
    def free(self) -> ContactForces:
        """What a call answers when no run touches any surface (the same object every time)."""
        return self._free

    def kinematics(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The touching frame's origin [m] (N, 3) and world-aligned Jacobian (N, 6, nv) at ``q``."""
        model, data, fid = self._model, self._data, self._frame
        n = q.shape[0]
        position = np.empty((n, 3))
        jacobian = np.empty((n, 6, model.nv))
        for i in range(n):
            jacobian[i] = pin.computeFrameJacobian(model, data, q[i], fid, WORLD_ALIGNED)
            position[i] = data.oMf[fid].translation
        return position, jacobian

    def __call__(self, q: np.ndarray, v: np.ndarray) -> ContactForces:
        last = self._last
        if last is not None and last[0] is q and last[1] is v:
            return last[2]
        forces = self._evaluate(q, v)
        self._last = (q, v, forces)
        return forces

    def _evaluate(self, q: np.ndarray, v: np.ndarray) -> ContactForces:
        """Every run by the same scalar code (:meth:`_run`): a batch equals its single runs bit
        for bit, and one run costs a Pinocchio call and a few microseconds of Python floats."""
        model, data, fid, run, origin = self._model, self._data, self._frame, self._run, self._origin
        touching: set[tuple[int, int]] = set()
        found = []
        for i in range(q.shape[0]):
            J = pin.computeFrameJacobian(model, data, q[i], fid, WORLD_ALIGNED)  # also sets data.oMf[fid]
            found.append(run(i, origin.translation.tolist(), J, v[i], touching))
        if not touching:
            if self._touching:
                self._touching, self._checked = set(), set()
            return self._free
        self._check_step(q, touching)
        if len(found) == 1:  # one run: its rows as they are
            wrench, tau, depth = found[0]  # type: ignore[misc]
            forces = ContactForces(wrench[None], tau[None], np.array([depth]))
        else:
            zero = self._zero_row
            rows = zip(*(zero if x is None else x for x in found), strict=True)
            forces = ContactForces(*(np.array(column) for column in rows))
        for array in forces:  # the law's sensor reads them as they are
            array.setflags(False)  # type: ignore[call-arg]
        return forces

    def _run(
        self, i: int, p: list[float], J: np.ndarray, v: np.ndarray, touching: set[tuple[int, int]]
    ) -> tuple[np.ndarray, np.ndarray, float] | None:
        """Run ``i``'s contact at its frame origin ``p`` [m] with Jacobian ``J`` and velocity ``v``:
        the wrench the contact point applies to the surfaces (6,), the joint torque on the arm
        (nv,) and the deepest penetration [m] (None out of contact); adds ``(i, surface)`` to
        ``touching`` where the sphere is inside."""
        px, py, pz = p
        r, eps2 = self._radius, self._eps2
        twist: list[float] | None = None
        fx = fy = fz = mx = my = mz = depth = 0.0
        for s, (nx, ny, nz, offset, k, b, mu, face) in enumerate(self._surfaces):
            d = nx * px + ny * py + nz * pz - offset  # d = n·(p − x) − r
            if d >= 0.0 or (face is not None and not _over(face, px - r * nx, py - r * ny, pz - r * nz, d)):
                continue
            touching.add((i, s))
            if twist is None:
                twist = (J @ v).tolist()
            vx, vy, vz, wx, wy, wz = twist
            lam = k * -d - b * (nx * vx + ny * vy + nz * vz)  # k δ + b δ̇, δ̇ = −n·ṗ
            lam = lam if lam > 0.0 else 0.0
            # the contact point c = p − r n slips at ṗ − r ω × n, less its normal part
            sx = vx - r * (wy * nz - wz * ny)
            sy = vy - r * (wz * nx - wx * nz)
            sz = vz - r * (wx * ny - wy * nx)
            sn = sx * nx + sy * ny + sz * nz
            sx, sy, sz = sx - sn * nx, sy - sn * ny, sz - sn * nz
            scale = mu * lam / math.sqrt(sx * sx + sy * sy + sz * sz + eps2)
            tx, ty, tz = -scale * sx, -scale * sy, -scale * sz  # friction on the arm
            fx, fy, fz = fx + lam * nx + tx, fy + lam * ny + ty, fz + lam * nz + tz
            # moment about the origin: (c − p) × f = −r n × f_t
            mx, my, mz = (
                mx - r * (ny * tz - nz * ty),
                my - r * (nz * tx - nx * tz),
                mz - r * (nx * ty - ny * tx),
            )
            depth = max(depth, -d)
        if twist is None:
            return None
        on_arm = np.array([fx, fy, fz, mx, my, mz])
        return -on_arm, on_arm @ J, depth

    def penetrations(self, q: np.ndarray) -> np.ndarray:
        """How far [m] the contact sphere is inside each surface at ``q`` (N, nv): shape (N, S),
        positive inside, 0 or below outside (or beside a bounded face)."""
        position, _ = self.kinematics(q)
        depth = self._offsets - position @ self._normals.T
        if self._bounded:
            depth = np.where(self._over_faces(position), depth, np.minimum(depth, 0.0))
        return depth

    def _over_faces(self, position: np.ndarray) -> np.ndarray:
        """(N, S): whether each contact point is over each surface's face."""
        centres = position[:, None, :] - self._radius * self._normals[None]
        return np.column_stack([s.over_face(centres[:, i]) for i, s in enumerate(self.scene.surfaces)])

    def check_starts(self, q: np.ndarray, touching: set[tuple[int, int]]) -> None:
        """As the engine steps a contact of its own (MuJoCo's): ``touching`` the ``(run, surface)``
        in contact at the state ``q`` (N, nv); each that starts checked (:meth:`_check_step`)."""
        self._check_step(q, touching)

    def _check_step(self, q: np.ndarray, touching: set[tuple[int, int]]) -> None:
        """Fail the run when a contact that starts here is too stiff for the step (the effective
        mass at the state where it starts; :func:`~twolink_pin.contact.stability.too_stiff`)."""
        starting = touching - self._touching
        self._touching = touching
        self._checked &= touching
        if self._step is None or not starting - self._checked:
            return
        for run, s in sorted(starting - self._checked):
            surface = self.scene.surfaces[s]
            J = pin.computeFrameJacobian(self._model, self._data, q[run], self._frame, WORLD_ALIGNED)
            mass = effective_mass(self._model, self._data, q[run], J[:3], self._normals[s])
            why = too_stiff(mass, surface.stiffness, surface.damping, self._step)
            self._checked.add((run, s))
            if why is not None:
                prefix = f"run {run}: " if self._runs > 1 else ""
                raise ContactError(surface.name, self.time, prefix + why)


Face = tuple[float, ...]
"""A bounded surface as floats: its point (3), its in-plane axes u, w (3 each), half length and
half width, depth [m]."""


def _face(surface: Surface) -> Face | None:
    """``surface``'s face as :data:`Face` (None for an unbounded plane)."""
    if surface.size is None:
        return None
    u, w = surface.axes()
    length, width, depth = surface.size
    return (*surface.point, *u.tolist(), *w.tolist(), length / 2, width / 2, depth)


def _over(face: Face, cx: float, cy: float, cz: float, d: float) -> bool:
    """Whether the contact point ``c`` [m] is over the face and less than its depth inside
    (``d`` its signed distance to the plane [m]): :meth:`Surface.over_face` on floats."""
    x0, y0, z0, ux, uy, uz, wx, wy, wz, half_length, half_width, depth = face
    ox, oy, oz = cx - x0, cy - y0, cz - z0
    return (
        abs(ox * ux + oy * uy + oz * uz) <= half_length
        and abs(ox * wx + oy * wy + oz * wz) <= half_width
        and d > -depth
    )


def check_start(robot: RobotModel, scene: Scene, q: np.ndarray) -> None:
    """Refuse runs that start inside a surface: ``q`` (N, nv) [rad], their initial configurations.

    Raises:
        InvalidParameterError: naming the surface, the penetration [mm] and the run (of several).
    """
    from twolink_pin.errors import InvalidParameterError

    q = np.atleast_2d(np.asarray(q, dtype=float))
    contact = CompliantContact(robot, scene, len(q))
    depth = contact.penetrations(q)
    if not (depth > 0).any():
        return
    run, s = (int(x) for x in np.argwhere(depth > 0)[0])
    surface = scene.surfaces[s]
    which = f"run {run}'s " if len(q) > 1 else ""
    raise InvalidParameterError(
        f"{which}initial configuration",
        f"q = {np.round(q[run], 6).tolist()} rad",
        f"a start outside the surfaces: the contact sphere (radius {scene.radius:g} m) is "
        f"{1e3 * depth[run, s]:.4g} mm inside surface '{surface.name}' (move the start or the surface)",
    )


__all__ = ["CompliantContact", "ContactForces", "check_start"]
