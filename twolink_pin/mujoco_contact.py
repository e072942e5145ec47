r"""The MuJoCo plant's contact: a scene's surfaces as MuJoCo geoms, MuJoCo's own soft contact,
and the force sensor's reading of it.

**Geometry** (:func:`add_scene`, given to :func:`~twolink_pin.mujoco_model.compile_model`): the
arm's contact sphere (the scene's ``radius`` [m]) is a ``sphere`` geom on the body of the touching
frame's joint, at the frame's placement (the frame's origin: as on the Pinocchio plant); an
unbounded surface is a ``plane`` geom through its point, its ``z`` the outward normal; a bounded
one a ``box`` geom whose top face is the surface (its centre ``depth/2`` below the point). Every
geom has ``contype = conaffinity = 0``: only the explicit pairs sphere–surface collide (one
``<pair>`` per surface, carrying its properties), no link collides with another. Contacts
start at zero distance (``margin`` 0): where the Pinocchio plant's do.

**Properties** (:func:`contact_parameters`). MuJoCo's soft contact solves, per contact, for the
constraint force ``f`` with the reference acceleration ``a_ref = −b v − k d r`` (``r`` the signed
distance [m], ``v`` its rate), the impedance ``d`` (``solimp``) and the regulariser ``R = (1−d)/d
Â`` (``Â`` MuJoCo's approximation of the contact's inverse mass, ``efc_diagApprox``: for a sphere
on a link against the world, the link's ``body_invweight0`` [1/kg], computed once at the model's
reference configuration). Unclamped, ``R f = −a − b v − k d r`` with ``a = A f + a₀`` the
contact's acceleration, i.e.

$$ f = \frac{k d}{R}\,\delta + \frac{b}{R}\,\dot\delta - \frac{1}{R}\,a, \qquad
\delta = -r, $$

a spring–damper of stiffness ``k d / R`` [N/m] and damping ``b / R`` [N·s/m] plus an added mass
``1/R`` along the normal. With ``solref`` in MuJoCo's direct form ``(−s, −c)`` and ``solimp =
(d, d, …)`` MuJoCo uses ``k = s/d²``, ``b = c/d``; so the scene's ``K`` [N/m] and ``B`` [N·s/m]
are exactly MuJoCo's with

$$ s = K (1-d)\,\hat A \ [1/\mathrm{s}^2], \qquad c = B (1-d)\,\hat A \ [1/\mathrm{s}], $$

and ``d`` = :data:`IMPEDANCE` (0.01) keeps the added mass ``1/R = d / ((1−d) Â)`` to 1 % of
MuJoCo's mass estimate: the two plants' contacts then differ by that mass only (a static push
by nothing: ``tests/test_mujoco_contact.py``). Coulomb's μ is the pair's sliding friction (both
tangent directions; torsional and rolling friction 0), with ``condim`` 3 and MuJoCo's elliptic
cone (``condim`` 1 when μ = 0). A surface that gives its own ``solref``/``solimp`` has them
as given (MuJoCo's meaning; K and B then unused on this plant).

**What differs from the Pinocchio plant's contact** (:mod:`twolink_pin.contact.compliant`):
MuJoCo's force is a constraint force: it never pulls (as the clip there), carries the added
mass above, and below the friction cone it is MuJoCo's soft "stick" (a tangential viscous force
``≈ B v_t``, capped at ``μ f_n``) where the Pinocchio plant's is ``μ λ v_t / √(v_t² + ε²)``;
while the ball slides the elliptic cone couples the normal and friction rows, so part of the
normal force is not the spring's (the ball penetrates less for the same force: ``f = K δ``
holds at rest and without friction); a box is touched on its sides and edges too (there only on
its top face).

**The force sensor** (:class:`MujocoContact`, :meth:`MujocoPlant.contact_model
<twolink_pin.mujoco_plant.MujocoPlant.contact_model>`) reads MuJoCo's contact force — a
function of the state *and* of the torque applied at it (the constraint is solved with the
accelerations) — from the plant's last ``mj_forward`` of that run: at an RK4 stage it reads the
force of the previous stage (half a step earlier at most, the torque then held), as a sampled
sensor would. The wrench is converted to the Pinocchio plant's: what the contact point applies
to the surfaces, world axes, about the touching frame's origin, linear rows first; the
penetration is MuJoCo's ``−dist`` of the deepest contact. The engine never adds its ``tau``: MuJoCo
applies the contact itself (:attr:`MujocoContact.pushes` False). A contact that starts too stiff
for the step fails the run as on the Pinocchio plant (the engine's RK4 integrates MuJoCo's
accelerations: the same stability limit, :mod:`twolink_pin.contact.stability`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twolink_pin.contact.compliant import CompliantContact, ContactForces
from twolink_pin.contact.scene import Scene, Surface
from twolink_pin.contact.stability import contact_frame
from twolink_pin.model import RobotModel

IMPEDANCE = 0.01
"""MuJoCo's impedance ``d`` of every contact (``solimp = (d, d, 0.001, 0.5, 2)``): the added mass
along the normal is ``d/(1−d)`` of MuJoCo's mass estimate (see the module docstring)."""
TIP = "twolink_pin_tip"
"""The contact sphere's geom name."""
SURFACE = "twolink_pin_surface_"
"""The prefix of the surfaces' geom names (then the surface's index)."""


def add_scene(robot: RobotModel, scene: Scene) -> Any:
    """A function that adds ``scene``'s geoms and pairs to an ``MjSpec`` (see the module docstring)."""

    def add(spec: Any) -> None:
        import mujoco

        frame = robot.model.frames[contact_frame(robot, scene)]
        body = spec.joint(str(robot.model.names[frame.parentJoint])).parent
        tip = body.add_geom(
            name=TIP,
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[scene.radius, 0.0, 0.0],
            pos=np.array(frame.placement.translation, dtype=float),
            contype=0,
            conaffinity=0,
            mass=0.0,
        )
        del tip
        for i, surface in enumerate(scene.surfaces):
            _add_surface(mujoco, spec, f"{SURFACE}{i}", surface)
            pair = spec.add_pair(name=f"twolink_pin_pair_{i}", geomname1=f"{SURFACE}{i}", geomname2=TIP)
            pair.condim = 3 if surface.friction > 0 else 1
            pair.margin = 0.0
            pair.gap = 0.0

    return add


def _add_surface(mujoco: Any, spec: Any, name: str, surface: Surface) -> None:
    """``surface`` as a plane (unbounded) or a box whose top face it is, on the world body."""
    u, w = surface.axes()
    n = surface.unit_normal
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.column_stack([u, w, n]).reshape(-1))
    point = np.array(surface.point, dtype=float)
    if surface.size is None:
        geom = spec.worldbody.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
        geom.pos = point
    else:
        length, width, depth = surface.size
        geom = spec.worldbody.add_geom(
            name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=[length / 2, width / 2, depth / 2]
        )
        geom.pos = point - 0.5 * depth * n
    geom.quat = quat
    geom.contype = 0
    geom.conaffinity = 0


def contact_parameters(surface: Surface, inverse_mass: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(solref, solimp)`` of ``surface``'s pair: its own if it gives them, else MuJoCo's direct
    form ``(−K (1−d) Â, −B (1−d) Â)`` [1/s², 1/s] with ``Â = inverse_mass`` [1/kg] and
    ``solimp = (d, d, 0.001, 0.5, 2)``, d = :data:`IMPEDANCE` (see the module docstring)."""
    d = IMPEDANCE
    solimp = surface.solimp or (d, d, 0.001, 0.5, 2.0)
    if surface.solref is not None:
        return tuple(surface.solref), tuple(solimp)
    dmax = solimp[1]
    scale = (1.0 - dmax) * inverse_mass
    return (-surface.stiffness * scale, -surface.damping * scale), tuple(solimp)


def set_contact_properties(mujoco: Any, model: Any, scene: Scene) -> None:
    """The compiled ``model``'s pairs given the scene's K, B, μ (:func:`contact_parameters`) and
    MuJoCo's elliptic friction cone."""
    tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, TIP)
    inverse_mass = float(model.body_invweight0[model.geom_bodyid[tip], 0])
    for i, surface in enumerate(scene.surfaces):
        solref, solimp = contact_parameters(surface, inverse_mass)
        model.pair_solref[i] = solref
        model.pair_solimp[i] = solimp
        mu = surface.friction
        model.pair_friction[i] = [mu, mu, 0.0, 0.0, 0.0]
    model.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC


class MujocoContact:
    """The MuJoCo plant's contact as the engine asks it (see the module docstring): calling it
    with ``(q, q̇)`` (N, nv) gives :class:`~twolink_pin.contact.ContactForces` read from the
    last ``mj_forward`` of the dynamics it follows (:meth:`follow`)."""

    pushes = False
    """MuJoCo applies the contact itself: the engine adds no ``tau``."""

    def __init__(
        self, model: Any, robot: RobotModel, scene: Scene, runs: int, step: float | None = None
    ) -> None:
        import mujoco

        self._mujoco = mujoco
        self.scene = scene
        self._runs = runs
        self._tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, TIP)
        self._surface = {
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{SURFACE}{i}"): i
            for i in range(len(scene.surfaces))
        }
        # the step's check where a contact starts (RK4 integrates MuJoCo's as the Pinocchio plant's)
        self._check = CompliantContact(robot, scene, runs, step) if step is not None else None
        self._datas: Any = list  # no dynamics followed yet: no run
        self._followed: Any = None
        self._model = model
        self._force = np.zeros(6)
        self._touching: set[tuple[int, int]] = set()
        self._free = ContactForces(np.zeros((runs, 6)), np.zeros((runs, model.nv)), np.zeros(runs))
        for array in self._free:
            array.setflags(write=False)
        self.time = 0.0

    @property
    def time(self) -> float:
        """The simulated time [s] of the step under way (set by the caller; a failure names it)."""
        return self._time

    @time.setter
    def time(self, t: float) -> None:
        self._time = t
        if self._check is not None:
            self._check.time = t

    @property
    def free(self) -> ContactForces:
        """What a call answers when no run touches (the same object every time)."""
        return self._free

    def follow(self, dynamics: Any) -> None:
        """Read the contacts of ``dynamics`` from now on: its ``datas()``, each run's ``MjData``
        after its last call (None: a run without contacts)."""
        followed = self._followed
        if followed is not None and dynamics is not followed:  # a payload step: the plant after it
            dynamics.resume(followed)  # its contacts at the last state read, before its first call
        self._followed = dynamics
        self._model, self._datas = dynamics.model, dynamics.datas

    def __call__(self, q: np.ndarray, v: np.ndarray) -> ContactForces:
        touching: set[tuple[int, int]] = set()
        run, datas = self._run, self._datas()
        if self._runs == 1:  # one run: no list of rows (this runs at every RK4 stage)
            rows = [None if datas[0] is None else run(datas[0], 0, touching)]
        else:
            rows = [None if data is None else run(data, i, touching) for i, data in enumerate(datas)]
        if touching != self._touching:
            if self._check is not None:
                self._check.check_starts(q, touching)  # a contact too stiff for the step fails the run
            self._touching = touching
        if not touching:
            return self._free
        if self._runs == 1:
            wrench, depth = np.array([rows[0][0]]), np.array([rows[0][1]])  # type: ignore[index]
        else:
            wrench, depth = np.zeros((self._runs, 6)), np.zeros(self._runs)
            for i, row in enumerate(rows):
                if row is not None:
                    wrench[i], depth[i] = row
        wrench.setflags(write=False)
        depth.setflags(write=False)
        return ContactForces(wrench, self._free.tau, depth)

    def _run(self, data: Any, run: int, touching: set[tuple[int, int]]) -> tuple[list[float], float] | None:
        """One run's wrench on the surfaces about the frame's origin (6,) and deepest
        penetration [m], from its ``MjData``; None out of contact. Adds ``(run, surface)`` to
        ``touching`` for each contact. On Python floats (one contact costs a few microseconds):
        the elliptic cone's force is ``efc_force[adr : adr + dim]`` in the contact frame (normal,
        then the two tangents: what ``mj_contactForce`` copies), the frame's rows are those axes
        in the world, the normal from geom1 to geom2 (the force on geom2)."""
        ncon = data.ncon
        if ncon == 0:
            return None
        tip, efc = self._tip, data.efc_force
        px, py, pz = data.geom_xpos[tip].tolist()
        fx = fy = fz = mx = my = mz = depth = 0.0
        found = False
        for i in range(ncon):
            contact = data.contact[i]
            adr = contact.efc_address
            if adr < 0:  # not in the constraint (excluded, or beyond the margin)
                continue
            found = True
            dim = contact.dim
            local = [*efc[adr : adr + min(dim, 3)].tolist(), 0.0, 0.0]
            n0, n1, n2, t0, t1, t2, s0, s1, s2 = contact.frame.tolist()
            fn, f1, f2 = local[0], local[1], local[2]
            wx, wy, wz = fn * n0 + f1 * t0 + f2 * s0, fn * n1 + f1 * t1 + f2 * s1, fn * n2 + f1 * t2 + f2 * s2
            geom1, geom2 = contact.geom.tolist()
            if geom2 != tip:  # the force on the arm
                wx, wy, wz = -wx, -wy, -wz
            touching.add((run, self._surface[geom1 if geom2 == tip else geom2]))
            cx, cy, cz = contact.pos.tolist()
            rx, ry, rz = cx - px, cy - py, cz - pz
            fx, fy, fz = fx + wx, fy + wy, fz + wz
            mx, my, mz = mx + ry * wz - rz * wy, my + rz * wx - rx * wz, mz + rx * wy - ry * wx
            depth = max(depth, -contact.dist)
        return ([-fx, -fy, -fz, -mx, -my, -mz], depth) if found else None


__all__ = ["IMPEDANCE", "MujocoContact", "add_scene", "contact_parameters", "set_contact_properties"]
