"""The rigid-body terms of :class:`~twolink_pin.controllers.Terms` beyond the model term:
``mass``, ``gravity``, ``bias``, ``solve_mass`` and ``frame``, for one run or N.

Each is one Pinocchio algorithm per run, on the controller's believed model (its robot, or
the robot with its ``model_parameters``, one model per run when the runs believe different
parameters, built the first time a law asks):

==============  ================================================================
``mass``        ``pin.crba`` (upper triangle), symmetrised; read-only, and reused when
                asked again for the same values (same dtype, shape and bytes)
``gravity``     ``pin.computeGeneralizedGravity``
``bias``        ``pin.nonLinearEffects`` (``Ĉ q̇ + ĝ``)
``solve_mass``  ``pin.crba`` then a batched linear solve (``numpy.linalg.solve``'s
                LU with pivoting, :mod:`twolink_pin.small_linalg`: no inverse is formed)
``inverse_dynamics_derivatives``  ``pin.computeRNEADerivatives`` at K states per run (τ, ∂τ/∂q,
                ∂τ/∂q̇, M̂: what a planning law linearises its plan's torque with)
``frame``       ``pin.forwardKinematics`` (q, q̇, 0) + ``pin.computeJointJacobians``,
                then ``getFrameJacobian`` and ``getFrameClassicalAcceleration`` in
                ``LOCAL_WORLD_ALIGNED`` (kinematics: the robot's own model); the
                last few results kept by value (the same state is asked again
                within a step)
==============  ================================================================

**One pass per state.** Once a law has asked for a dynamics term (``mass``, ``gravity``,
``bias``, ``solve_mass``), its ``frame`` calls run one ``pin.computeAllTerms`` per run
instead of the forward kinematics: the same pass gives the frame's pose, Jacobian and
``J̇ q̇`` (bit for bit as above: the same kinematic recursions) and ``M̂`` (upper triangle),
``Ĉ q̇ + ĝ`` and ``ĝ`` at that state, read from the ``Data``'s own arrays and kept by value,
so that the law's ``mass``, ``bias`` and ``gravity`` at the same state cost no second
Pinocchio call. (``M̂`` and ``ĝ`` of that pass agree with ``crba`` and
``computeGeneralizedGravity`` to rounding: world-frame recursions.) A law that asks only
for the frame (or a caller such as the wrench events) keeps the lighter kinematics.

Every array returned is read-only (:func:`frozen`). A batch computes every run with the same calls as a single run, so a batch equals N
single runs bit for bit. The runs are looped over in Python: these terms cost about
N × (one Pinocchio call + 2 µs) per evaluation.

:class:`RigidBodyTermsMixin` gives :class:`~twolink_pin.simulation.terms.SingleRunTerms`
and :class:`~twolink_pin.simulation.terms.BatchTerms` these methods; they set
``self._rigid`` to a :class:`RigidBodyTerms`.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from twolink_pin.controllers.law_io import FrameTerms
from twolink_pin.dynamics import InverseDynamicsDerivatives, inverse_dynamics_derivatives
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.model.parameters import model_with_parameters
from twolink_pin.small_linalg import solve

WORLD_ALIGNED = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
"""The one convention of :meth:`RigidBodyTerms.frame`."""


FRAME_CACHE = 4
"""Frame results kept by value (:meth:`RigidBodyTerms.frame`): the law's state and the
reference's, for a frame or two."""


def frozen(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only in place and returned: every array a law gets from ``Terms``
    (a law that writes into one raises; the engine's containment names the law)."""
    # write=False, positionally (numpy's documented signature; its stubs say keyword-only): half the cost
    a.setflags(False)  # type: ignore[call-arg]
    return a


class RigidBodyTerms:
    """M̂, ĝ, Ĉq̇ + ĝ, M̂⁻¹b and frame kinematics on a controller's model, for N runs.

    Args:
        robot: The robot (kinematics, parameter map, end-effector frame).
        parameters: The believed parameters ``p``: None (the robot's own), shape (n_p,)
            or (1, n_p) for every run, or (N, n_p) one row per run.
    """

    def __init__(self, robot: RobotModel, parameters: np.ndarray | None) -> None:
        self._robot = robot
        self._kinematics = robot.model
        self._kinematics_data = robot.model.createData()
        self._nv = robot.nv
        p = None if parameters is None else np.asarray(parameters, dtype=float)
        if p is not None and p.ndim == 2 and p.shape[0] == 1:
            p = p[0]
        self._p = p
        self._models: list[pin.Model] | None = None
        self._data: pin.Data | None = None
        self._frames: dict[str | None, int] = {None: robot.ee_frame_id}
        self._zero = np.zeros(robot.nv)
        self._lower = np.tril(np.ones((robot.nv, robot.nv), dtype=bool), -1)
        self._last_mass: tuple[tuple[object, ...], np.ndarray] | None = None
        self._last_bias: tuple[tuple[object, ...], np.ndarray] | None = None
        self._last_gravity: tuple[tuple[object, ...], np.ndarray] | None = None
        self._frame_cache: dict[tuple[object, ...], FrameTerms] = {}
        self._fused = False  # set when the law asks for a dynamics term: frame() then fills them too

    # -- models ------------------------------------------------------------------------

    def _dynamics(self) -> tuple[list[pin.Model], pin.Data]:
        if self._models is None:
            robot, p = self._robot, self._p
            if p is None:
                self._models = [robot.model]
            elif p.ndim == 1:
                self._models = [model_with_parameters(robot.model, robot.parameter_map, p)]
            else:
                self._models = [model_with_parameters(robot.model, robot.parameter_map, row) for row in p]
            self._data = self._models[0].createData()
        assert self._data is not None
        return self._models, self._data

    def _rows(self, *arrays: np.ndarray) -> tuple[int, list[pin.Model], pin.Data]:
        # ``arrays``: 2-D ndarrays (:meth:`_matrix`); a plain loop (called at every RK4 stage)
        models, data = self._dynamics()
        n = len(models)
        for a in arrays:
            if a.shape[0] > n:
                n = a.shape[0]
        if len(models) > 1 and any(a.shape[0] not in (1, n) for a in arrays):
            raise InvalidParameterError(
                "q", f"shape {arrays[0].shape}", f"one row, or one per run ({len(models)})"
            )
        return n, models, data

    def _states(self, q: np.ndarray, n: int) -> np.ndarray:
        if type(q) is np.ndarray and q.shape == (n, self._nv) and q.dtype == np.float64:
            return q  # the engine's (N, nv) state as it is: no conversion, no broadcast
        q = np.asarray(q, dtype=float)
        if q.ndim == 1:
            q = q[None]
        return np.broadcast_to(q, (n, self._nv))

    @staticmethod
    def _matrix(a: np.ndarray) -> np.ndarray:
        """``a`` as a 2-D array (the engine's (N, nv) state as it is)."""
        if type(a) is np.ndarray and a.ndim == 2:
            return a
        return np.atleast_2d(a)

    # -- terms -------------------------------------------------------------------------

    def _symmetric(self, upper: np.ndarray) -> np.ndarray:
        """(N, nv, nv) upper triangles (Pinocchio's CRBA) made symmetric, read-only."""
        return frozen(np.where(self._lower, upper.transpose(0, 2, 1), upper))

    def mass(self, q: np.ndarray) -> np.ndarray:
        q = self._matrix(q)
        self._fused = True
        # Asked twice per law call (solve_mass, then mass), and filled by frame()'s pass:
        # reused when q has the same shape and the same bytes (exact values; no copy kept).
        key = (q.dtype, q.shape, q.tobytes())
        last = self._last_mass
        if last is not None and last[0] == key:
            return last[1]
        n, models, data = self._rows(q)
        Q = self._states(q, n)
        out = np.empty((n, self._nv, self._nv))
        for i in range(n):
            out[i] = pin.crba(models[i % len(models)], data, Q[i])  # the upper triangle
        out = self._symmetric(out)
        self._last_mass = (key, out)
        return out

    def gravity(self, q: np.ndarray) -> np.ndarray:
        q = self._matrix(q)
        self._fused = True
        last = self._last_gravity  # set by frame()'s pass only (a law without it pays no key)
        if last is not None and last[0] == (q.dtype, q.shape, q.tobytes()):
            return last[1]
        n, models, data = self._rows(q)
        Q = self._states(q, n)
        out = np.empty((n, self._nv))
        for i in range(n):
            out[i] = pin.computeGeneralizedGravity(models[i % len(models)], data, Q[i])
        return frozen(out)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        q, v = self._matrix(q), self._matrix(v)
        self._fused = True
        last = self._last_bias  # set by frame()'s pass only
        if last is not None and last[0] == (q.dtype, v.dtype, q.shape, v.shape, q.tobytes(), v.tobytes()):
            return last[1]
        n, models, data = self._rows(q, v)
        Q, V = self._states(q, n), self._states(v, n)
        out = np.empty((n, self._nv))
        for i in range(n):
            out[i] = pin.nonLinearEffects(models[i % len(models)], data, Q[i], V[i])
        return frozen(out)

    def solve_mass(self, q: np.ndarray, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if b.ndim not in (2, 3) or b.shape[1] != self._nv:
            raise InvalidParameterError(
                "b",
                f"shape {b.shape}",
                f"(N, {self._nv}) or (N, {self._nv}, k): one vector or matrix per run",
            )
        M = self.mass(q)  # (sets _fused)
        n = max(M.shape[0], b.shape[0])
        if M.shape[0] != n:
            M = np.broadcast_to(M, (n, self._nv, self._nv))
        if b.ndim == 2:
            return frozen(solve(M, np.broadcast_to(b, (n, self._nv))[..., None])[..., 0])
        return frozen(solve(M, b if b.shape[0] == n else np.broadcast_to(b, (n, *b.shape[1:]))))

    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> InverseDynamicsDerivatives:
        q, v, a = (np.asarray(x, dtype=float) for x in (q, v, a))
        if q.ndim != 3 or q.shape[2] != self._nv or v.shape != q.shape or a.shape != q.shape:
            raise InvalidParameterError(
                "q, v, a",
                f"shapes {q.shape}, {v.shape}, {a.shape}",
                f"(N, K, {self._nv}) each: K states of each of N runs",
            )
        models, data = self._dynamics()
        n = q.shape[0]
        if len(models) > 1 and n != len(models):
            raise InvalidParameterError(
                "q", f"shape {q.shape}", f"one block of states per run ({len(models)})"
            )
        parts = [
            inverse_dynamics_derivatives(models[i % len(models)], data, q[i], v[i], a[i]) for i in range(n)
        ]
        return InverseDynamicsDerivatives(*(frozen(np.stack(x)) for x in zip(*parts, strict=True)))

    def frame_id(self, frame: str | None) -> int:
        """Index of ``frame`` in the model (None: the end effector)."""
        fid = self._frames.get(frame)
        if fid is None:
            model = self._kinematics
            if not isinstance(frame, str) or not model.existFrame(frame):
                names = [f.name for f in model.frames]
                raise InvalidParameterError("frame", frame, f"a frame of {self._robot.name}: one of {names}")
            fid = int(model.getFrameId(frame))
            self._frames[frame] = fid
        return fid

    def frame(self, q: np.ndarray, v: np.ndarray, frame: str | None = None) -> FrameTerms:
        fid = self.frame_id(frame)
        q, v = self._matrix(q), self._matrix(v)
        # The same (q, q̇) is asked again within a step (the reference's frame at RK4 stages 2
        # and 3, and at stage 4 and the next step's stage 1): the last FRAME_CACHE results by
        # value (read-only, so sharing them is safe).
        key = (fid, q.shape, v.shape, q.tobytes(), v.tobytes())
        cache = self._frame_cache
        hit = cache.get(key)
        if hit is not None:
            return hit
        result = self._frame(fid, q, v, key)
        if len(cache) >= FRAME_CACHE:
            del cache[next(iter(cache))]
        cache[key] = result
        return result

    def _frame(self, fid: int, q: np.ndarray, v: np.ndarray, key: tuple[object, ...]) -> FrameTerms:
        n = max(q.shape[0], v.shape[0])
        if self._fused:
            models, data = self._dynamics()
            if len(models) == 1 and q.shape == v.shape == (1, self._nv) and q.dtype == v.dtype == np.float64:
                return self._fused_one(fid, q, v, key, models[0], data)
        Q, V = self._states(q, n), self._states(v, n)
        if self._fused:
            models, data = self._dynamics()
            if len(models) in (1, n):
                return self._fused_pass(fid, q, v, Q, V, models, data)
        model, data, zero = self._kinematics, self._kinematics_data, self._zero
        placement = np.empty((n, 4, 4))  # homogeneous, as in _fused_pass
        jacobian = np.empty((n, 6, self._nv))
        drift = np.empty((n, 6))
        for _, qi, vi, H, J, a in zip(range(n), Q, V, placement, jacobian, drift, strict=False):  # as above
            pin.forwardKinematics(model, data, qi, vi, zero)
            pin.computeJointJacobians(model, data)
            H[...] = pin.updateFramePlacement(model, data, fid).homogeneous
            J[...] = pin.getFrameJacobian(model, data, fid, WORLD_ALIGNED)
            a[...] = pin.getFrameClassicalAcceleration(model, data, fid, WORLD_ALIGNED).vector
        return _frame_terms(placement, jacobian, drift)

    def _fused_pass(
        self,
        fid: int,
        q: np.ndarray,
        v: np.ndarray,
        Q: np.ndarray,
        V: np.ndarray,
        models: list[pin.Model],
        data: pin.Data,
    ) -> FrameTerms:
        """The frame by one ``pin.computeAllTerms`` per run, with ``M̂``, ``Ĉ q̇ + ĝ`` and ``ĝ`` of
        the same pass kept by value for :meth:`mass`, :meth:`bias`, :meth:`gravity`."""
        n, nv = Q.shape
        placement = np.empty((n, 4, 4))  # homogeneous: one Python-level copy instead of two
        jacobian = np.empty((n, 6, nv))
        drift = np.empty((n, 6))
        upper = np.empty((n, nv, nv))
        bias = np.empty((n, nv))
        gravity = np.empty((n, nv))
        # The Data's own arrays (views that Pinocchio fills in place at every call)
        M_data, bias_data, gravity_data = data.M, data.nle, data.g
        runs_models = models if len(models) == n else [models[0]] * n
        # Each run's rows as views (``row[...] = x`` costs less than ``out[i] = x``). Every
        # sequence has n rows, and the list comes first: zip stops on it without asking the
        # arrays for a row past their end (numpy formats an IndexError message for each,
        # ~4k instructions: what strict=True would cost a single run, 9 times).
        rows = zip(runs_models, Q, V, placement, jacobian, drift, upper, bias, gravity, strict=False)
        for model, qi, vi, H, J, a, M, b, g in rows:
            pin.computeAllTerms(model, data, qi, vi)
            H[...] = pin.updateFramePlacement(model, data, fid).homogeneous
            J[...] = pin.getFrameJacobian(model, data, fid, WORLD_ALIGNED)
            a[...] = pin.getFrameClassicalAcceleration(model, data, fid, WORLD_ALIGNED).vector
            M[...] = M_data
            b[...] = bias_data
            g[...] = gravity_data
        if q.shape[0] == n:
            self._last_mass = ((q.dtype, q.shape, q.tobytes()), self._symmetric(upper))
            self._last_gravity = ((q.dtype, q.shape, q.tobytes()), frozen(gravity))
            if v.shape[0] == n:
                key = (q.dtype, v.dtype, q.shape, v.shape, q.tobytes(), v.tobytes())
                self._last_bias = (key, frozen(bias))
        return _frame_terms(placement, jacobian, drift)

    def _fused_one(
        self,
        fid: int,
        q: np.ndarray,
        v: np.ndarray,
        key: tuple[object, ...],
        model: pin.Model,
        data: pin.Data,
    ) -> FrameTerms:
        """:meth:`_fused_pass` of one run ((1, nv) float64 ``q``, ``v``; ``key``: :meth:`frame`'s,
        whose last two items are their bytes): the same Pinocchio calls on the same rows, the
        results taken as the fresh arrays Pinocchio returns (the placement's homogeneous matrix,
        the Jacobian) or copied out of the ``Data`` (M̂ symmetrised straight from it), without
        the batch's buffers and row copies."""
        pin.computeAllTerms(model, data, q[0], v[0])
        H = pin.updateFramePlacement(model, data, fid).homogeneous  # a new (4, 4) array
        jacobian = pin.getFrameJacobian(model, data, fid, WORLD_ALIGNED)[None]  # a new array
        # .vector is a view into a temporary Motion: copied
        drift = np.array(pin.getFrameClassicalAcceleration(model, data, fid, WORLD_ALIGNED).vector)[None]
        M = data.M  # the upper triangle, in the Data: np.where makes the new symmetric array
        q_key = (q.dtype, q.shape, key[3])
        self._last_mass = (q_key, frozen(np.where(self._lower, M.T, M)[None]))
        self._last_gravity = (q_key, frozen(data.g[None].copy()))
        self._last_bias = (
            (q.dtype, v.dtype, q.shape, v.shape, key[3], key[4]),
            frozen(data.nle[None].copy()),
        )
        position = np.ascontiguousarray(H[None, :3, 3])
        rotation = np.ascontiguousarray(H[None, :3, :3])
        return FrameTerms(frozen(position), frozen(rotation), frozen(jacobian), frozen(drift))


def _frame_terms(placement: np.ndarray, jacobian: np.ndarray, drift: np.ndarray) -> FrameTerms:
    """Read-only :class:`FrameTerms` from (N, 4, 4) homogeneous placements (position and rotation
    copied out contiguous), Jacobians and drifts."""
    position = np.ascontiguousarray(placement[:, :3, 3])
    rotation = np.ascontiguousarray(placement[:, :3, :3])
    return FrameTerms(frozen(position), frozen(rotation), frozen(jacobian), frozen(drift))


class RigidBodyTermsMixin:
    """The rigid-body methods of :class:`~twolink_pin.controllers.Terms`, delegated
    to ``self._rigid`` (a :class:`RigidBodyTerms`)."""

    _rigid: RigidBodyTerms

    def mass(self, q: np.ndarray) -> np.ndarray:
        return self._rigid.mass(q)

    def gravity(self, q: np.ndarray) -> np.ndarray:
        return self._rigid.gravity(q)

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self._rigid.bias(q, v)

    def solve_mass(self, q: np.ndarray, b: np.ndarray) -> np.ndarray:
        return self._rigid.solve_mass(q, b)

    def frame(self, q: np.ndarray, v: np.ndarray, frame: str | None = None) -> FrameTerms:
        return self._rigid.frame(q, v, frame)

    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> InverseDynamicsDerivatives:
        return self._rigid.inverse_dynamics_derivatives(q, v, a)
