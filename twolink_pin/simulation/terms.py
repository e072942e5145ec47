"""The Pinocchio terms a law asks for (:class:`~twolink_pin.controllers.Terms`), for N runs.

:func:`terms_for` builds what the engine passes to ``Controller.compute``:

* **one run** (:class:`SingleRunTerms`): the model term ``M̂ a + Ĉ(q, v) w + ĝ`` by one
  ``pin.rnea`` on the :func:`~twolink_pin.dynamics.polarisation_pair` of the law's model,
  the regressor by one ``pin.computeJointTorqueRegressor`` on the same pair (the
  difference of its diagonal blocks, times the parameter map);
* **N runs** (:class:`BatchTerms`): ``pin.rneaInParallel`` over a ``pin.ModelPool``. The
  model term of a law whose runs share one model is one call on that model's pair. The
  regressor is built column by column from RNEA, which is linear in the inertial
  parameters π: on models that differ from a base ``π₀`` by the map's column ``P_j``,
  ``Y_j = τ(π₀ + P_j) − τ(π₀)``, all columns in one call on a
  :func:`~twolink_pin.dynamics.polarisation_forest`. Columns that are a constant matrix
  times ``a`` (no q, velocity or gravity dependence: e.g. the twolink's p1 and p2) are
  detected numerically once and evaluated as that matrix, with no RNEA. When the law's
  runs believe different parameters, its model term is ``Y p`` per run. For maps of many
  columns (:data:`REGRESSOR_BY_RUN_COLUMNS`: the 6- and 7-joint arms' base parameters) the
  regressor is one ``computeJointTorqueRegressor`` per run on the pair instead (4.3× faster
  on the UR5 and the Panda than 2 RNEA per column); the forests are cut into groups of at
  most :data:`FOREST_NV` joints (Pinocchio's ``Data`` grows as nv³).

``mass``, ``gravity``, ``bias``, ``solve_mass`` and ``frame`` are one Pinocchio algorithm per
run on the believed model (:mod:`twolink_pin.simulation.rigid_terms`).

Every array a law gets from these terms is read-only (:func:`~twolink_pin.simulation.rigid_terms.frozen`):
a law that writes into one raises, and the engine's containment names the law.

Every run's numbers are computed by the same code whatever N and whichever runs share its
batch (element-wise numpy, one Pinocchio evaluation per column), so a batch equals N
single runs to rounding and a run's result does not depend on how a sweep is chunked.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from twolink_pin import openmp
from twolink_pin.dynamics import friction_regressor, polarisation_forest, polarisation_pair
from twolink_pin.errors import InvalidParameterError, TwolinkPinError
from twolink_pin.model.parameters import (
    N_BODY_PARAMETERS,
    ParameterMap,
    inertial_parameters,
    model_with_parameters,
    with_inertial_parameters,
)
from twolink_pin.simulation.rigid_terms import RigidBodyTerms, RigidBodyTermsMixin, frozen

if TYPE_CHECKING:
    from twolink_pin.controllers import Controller

MIN_RUNS_PER_THREAD = 256
"""Fewer runs than this per thread and a batch uses fewer threads: a parallel region on a
handful of columns costs more in synchronisation than it saves."""


class BatchUnavailableError(TwolinkPinError):
    """Pinocchio lacks the parallel algorithms the batch engine needs.

    Attributes:
        missing: Names of the missing ``pinocchio`` attributes.
    """

    _fields = ("missing",)

    def __init__(self, missing: Sequence[str]) -> None:
        self.missing = tuple(missing)
        super().__init__(
            f"pinocchio {pin.__version__} has no {', '.join(self.missing)}: it was built without its "
            "parallel module (OpenMP). Install a build that has it (pip install 'pin>=3' or conda-forge "
            "pinocchio), or run the cases one by one with twolink_pin.simulate"
        )


def check_parallel() -> None:
    """Raise :class:`BatchUnavailableError` unless Pinocchio has its parallel algorithms."""
    missing = [name for name in ("ModelPool", "abaInParallel", "rneaInParallel") if not hasattr(pin, name)]
    if missing:
        raise BatchUnavailableError(missing)


def default_threads() -> int:
    """The default thread count: ``TWOLINK_PIN_THREADS`` if set, else the cores this process
    may use less those other work keeps busy (:func:`twolink_pin.openmp.default_threads`)."""
    return openmp.default_threads()


def threads_for(runs: int, threads: int | None) -> int:
    """Threads a batch of ``runs`` uses: at most one per :data:`MIN_RUNS_PER_THREAD` runs."""
    requested = default_threads() if threads is None else threads
    if not (isinstance(requested, int) and not isinstance(requested, bool) and requested >= 1):
        raise InvalidParameterError("threads", threads, "a whole number >= 1")
    return max(1, min(requested, runs // MIN_RUNS_PER_THREAD))


# -- one run ---------------------------------------------------------------------------------


_CONCATENATE = getattr(np.concatenate, "_implementation", np.concatenate)
"""``np.concatenate``'s C function without NumPy's array-function dispatch (a Python-level
dispatcher around it: a third of the call's cost on four (1, nv) rows, ~1 µs a step); the
arrays it joins here are the engine's and a law's, handed on to Pinocchio."""


def _pair_inputs(
    nv: int,
) -> Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]:
    """``fill(q, v, w, a)``: the pair's RNEA inputs ``Q = (q, q)``, ``V = ((v+w)/2, (v−w)/2)``,
    ``A = (a, 0)``, each of shape (2 nv,), valid until the next call.

    Built in one product ``[q v w a] T`` with a constant 0/±1/±½ matrix ``T``: two numpy
    calls instead of five (each entry is one input, or a half-sum that FMA or not rounds
    exactly like ``(v ± w)/2``). A closure over its buffers: no attribute lookups, four
    times per RK4 step.
    """
    eye = np.eye(nv)
    T = np.zeros((4 * nv, 6 * nv))
    T[0:nv, 0:nv] = T[0:nv, nv : 2 * nv] = eye  # q -> both copies
    T[nv : 2 * nv, 2 * nv : 3 * nv] = T[nv : 2 * nv, 3 * nv : 4 * nv] = 0.5 * eye  # v/2 -> both
    T[2 * nv : 3 * nv, 2 * nv : 3 * nv] = 0.5 * eye  # +w/2 -> copy A
    T[2 * nv : 3 * nv, 3 * nv : 4 * nv] = -0.5 * eye  # −w/2 -> copy B
    T[3 * nv :, 4 * nv : 5 * nv] = eye  # a -> copy A; copy B's acceleration stays 0
    # Written in place at every call: the arguments and the product live in these two
    # buffers, and (Q, V, A) are views of the product made once. They only ever reach
    # Pinocchio, which copies them; never a law.
    x = np.empty((1, 4 * nv))
    b = np.empty((1, 6 * nv))
    views = (b[0, : 2 * nv], b[0, 2 * nv : 4 * nv], b[0, 4 * nv :])
    concatenate, product = _CONCATENATE, x.dot

    def fill(q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, ...]:
        try:
            concatenate((q, v, w, a), 1, x)  # axis, out: positionally
        except (ValueError, np.exceptions.AxisError):  # a (nv,) argument: bring it to (1, nv)
            concatenate([np.reshape(y, (1, nv)) for y in (q, v, w, a)], 1, x)
        # ndarray.dot: the same BLAS product as matmul at half its per-call cost (each entry
        # sums at most two exact products: rounded once either way).
        product(T, b)
        return views

    return fill


class SingleRunTerms(RigidBodyTermsMixin):
    """:class:`~twolink_pin.controllers.Terms` for one run (arrays of shape (1, nv))."""

    def __init__(self, controller: Controller) -> None:
        robot = controller.robot
        model = robot.model
        p = controller.model_parameters
        if p is not None:
            model = model_with_parameters(model, robot.parameter_map, np.asarray(p).reshape(-1))
        self._pair = polarisation_pair(model)
        self._data = self._pair.createData()
        self._nv = robot.nv
        self._fill = _pair_inputs(robot.nv)
        self._n_pi = N_BODY_PARAMETERS * (model.njoints - 1)
        self._P = np.ascontiguousarray(robot.parameter_map.matrix)
        self._rigid = RigidBodyTerms(robot, p)
        # τ_A − τ_B as one product with [I; −I] (2 nv, nv): each entry sums one exact product of
        # each copy (the others are zeros), rounded once as the subtraction is — at half the cost
        # of two slices and a subtraction, four times a step
        eye = np.eye(robot.nv)
        self._difference = np.concatenate((eye, -eye))

    def model(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        tau = pin.rnea(self._pair, self._data, *self._fill(q, v, w, a))[None].dot(self._difference)
        tau.setflags(False)  # frozen(), inline: write=False, positionally
        return tau

    def regressor(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        nv, n_pi = self._nv, self._n_pi
        R = pin.computeJointTorqueRegressor(self._pair, self._data, *self._fill(q, v, w, a))
        return frozen((R[:nv, :n_pi] - R[nv:, n_pi:]).dot(self._P)[None])  # dot: matmul's BLAS call, cheaper

    def friction_regressor(self, v: np.ndarray, smoothing: float = 0.0) -> np.ndarray:
        return frozen(friction_regressor(np.reshape(v, (1, self._nv)), smoothing))


# -- N runs ----------------------------------------------------------------------------------


def _rows(x: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``x`` as ``shape`` (N, nv): itself when it has that shape already (a law's (N, nv) state and
    products; ``np.broadcast_to`` is a Python function: ~2 µs a call, a dozen calls a step), else
    a read-only broadcast view of it (a (1, nv) reference row)."""
    return x if getattr(x, "shape", None) == shape else np.broadcast_to(x, shape)


FOREST_NV = 48
"""Largest number of joints of one polarisation forest. Pinocchio's ``Data`` holds nv × nv × nv
second-derivative tensors, so one forest of all the regressor's column models (the UR5's 37
pairs: 444 joints) would take gigabytes and tens of seconds to allocate; forests of at most
48 joints take a few MB each and cost one ``rneaInParallel`` call more per group."""


class _PolarisedTerms:
    """``M_i(q) a + C_i(q, v) w + g_i(q)`` [N·m] of several models over the batch.

    ``rneaInParallel`` on :func:`~twolink_pin.dynamics.polarisation_forest` s of the models
    (same kinematics): the two terms of the polarisation identity of every model of a group in
    one parallel region, groups of at most :data:`FOREST_NV` joints.
    """

    def __init__(self, models: Sequence[pin.Model], threads: int, n: int) -> None:
        self.threads = threads
        self.k, self.nv = len(models), models[0].nv
        per_group = max(1, FOREST_NV // (2 * self.nv))
        self.groups = []
        for first in range(0, self.k, per_group):
            members = models[first : first + per_group]
            size = 2 * len(members) * self.nv
            pool = pin.ModelPool(polarisation_forest(members), threads)
            buffers = (np.empty((n, size)), np.empty((n, size)), np.zeros((n, size)), np.empty((n, size)))
            # τ_A − τ_B of each member as one product with [I; −I] blocks (size, k nv): each entry
            # sums one exact product of each copy, rounded once as the subtraction is (a third of
            # the cost of k strided subtractions)
            difference = np.kron(np.eye(len(members)), np.concatenate((np.eye(self.nv), -np.eye(self.nv))))
            self.groups.append((len(members), pool, buffers, difference))

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> list[np.ndarray]:
        nv = self.nv
        n = q.shape[0]
        plus, minus = 0.5 * (v + w), 0.5 * (v - w)
        a_full = _rows(a, (n, nv))
        terms: list[np.ndarray] = []
        for k, pool, (Q, V, A, out), difference in self.groups:
            Q.reshape(n, 2 * k, nv)[:] = q[:, None, :]
            velocities = V.reshape(n, k, 2, nv)
            velocities[:, :, 0, :] = plus[:, None, :]
            velocities[:, :, 1, :] = minus[:, None, :]
            A.reshape(n, k, 2, nv)[:, :, 0, :] = a_full[:, None, :]  # copies B keep a = 0
            pin.rneaInParallel(self.threads, pool, Q.T, V.T, A.T, out.T)
            both = out.dot(difference)
            terms += [both[:, i * nv : (i + 1) * nv] for i in range(k)]
        return terms


class _Regressor:
    """``Y_p(q, v, w, a)`` with ``Y_p p = M a + C(q, v) w + g`` over the batch: a list of
    n_p arrays of shape (N, nv), one per column of the parameter map.

    π₀ is ``model``'s parameters with any zero mass set to 1 kg, so that every column model
    ``π₀ + P_j`` has a finite inertia. Constant columns (``Y_j = C_j a``, checked at
    random states) are evaluated as ``a C_jᵀ``. When the map describes π₀'s dynamics
    completely, ``τ(π₀) = Y p₀`` gives the base term from the column models themselves
    (no base model); otherwise the base model is computed too.
    """

    def __init__(self, model: pin.Model, parameter_map: ParameterMap, threads: int, n: int) -> None:
        pi0 = inertial_parameters(model)
        masses = pi0[::N_BODY_PARAMETERS]
        masses[masses <= 0] = 1.0
        pi0[::N_BODY_PARAMETERS] = masses
        base = with_inertial_parameters(model, pi0)
        P = parameter_map.matrix
        size = P.shape[1]
        self.size = size
        columns = [with_inertial_parameters(model, pi0 + P[:, j]) for j in range(size)]
        probe = _Probe(model.nv)
        direct = probe.evaluate([base, *columns])
        y = [column - direct[0] for column in direct[1:]]
        self.constant: dict[int, np.ndarray] = {}
        for j in range(size):
            C = probe.constant_matrix(y[j])
            if C is not None:
                self.constant[j] = np.ascontiguousarray(C.T)
        self.varying = [j for j in range(size) if j not in self.constant]
        p0 = parameter_map.values(base)
        weights = p0[self.varying]
        denominator = 1.0 + float(np.sum(weights))
        self.base_weights: np.ndarray | None = None
        if self.varying and abs(denominator) > 1e-6:
            # τ(π₀) (1 + Σ_{j varying} p0_j) = Σ_{j constant} p0_j Y_j + Σ_{j varying} p0_j T_j
            predicted = sum((p0[j] * y[j] for j in self.constant), np.zeros_like(direct[0]))
            predicted = predicted + sum(p0[j] * direct[1 + j] for j in self.varying)
            if _close(predicted / denominator, direct[0]):
                self.base_weights = p0 / denominator
        models = [columns[j] for j in self.varying]
        if self.base_weights is None and self.varying:
            models = [base, *models]
        self.terms = _PolarisedTerms(models, threads, n) if models else None

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray | None] = [None] * self.size
        a_full = _rows(a, q.shape)
        for j, Ct in self.constant.items():
            out[j] = a_full @ Ct
        if self.terms is not None:
            terms = self.terms(q, v, w, a)
            if self.base_weights is None:
                base, varying = terms[0], terms[1:]
            else:
                varying = terms
                weights = self.base_weights
                base = None
                for j in self.constant:
                    base = out[j] * weights[j] if base is None else base + out[j] * weights[j]
                for j, term in zip(self.varying, varying, strict=True):
                    base = term * weights[j] if base is None else base + term * weights[j]
            for j, term in zip(self.varying, varying, strict=True):
                out[j] = term - base
        return out  # type: ignore[return-value]


class _RegressorByRun:
    """``Y_p(q, v, w, a)`` over the batch run by run: one ``computeJointTorqueRegressor`` on
    the :func:`~twolink_pin.dynamics.polarisation_pair` per run (as a single run computes
    it), the difference of its diagonal blocks times the map. For maps of many columns
    (the UR5's 36 base parameters) this is cheaper than 2 RNEA per column and run."""

    def __init__(self, model: pin.Model, parameter_map: ParameterMap) -> None:
        self.pair = polarisation_pair(model)
        self.data = self.pair.createData()
        self.nv = model.nv
        self.n_pi = N_BODY_PARAMETERS * (model.njoints - 1)
        self.P = np.ascontiguousarray(parameter_map.matrix)
        self.size = self.P.shape[1]
        self._buffer: np.ndarray | None = None  # the runs' pair regressors, (N, 2 nv, 2 n_pi)

    def __call__(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> list[np.ndarray]:
        Y = self.matrix(q, v, w, a)
        return [Y[:, :, j] for j in range(self.size)]

    def matrix(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``Y_p`` of every run, shape (N, nv, n_p): the loop over the runs only copies each
        pair regressor; the blocks' difference and the map are one product for all runs
        (per run the same BLAS product as a single run's)."""
        nv, n_pi = self.nv, self.n_pi
        n = q.shape[0]
        Q = np.concatenate((q, q), axis=1)
        V = np.concatenate((0.5 * (v + w), 0.5 * (v - w)), axis=1)
        A = np.concatenate((np.broadcast_to(a, (n, nv)), np.zeros((n, nv))), axis=1)
        R = self._buffer
        if R is None or R.shape[0] != n:
            R = self._buffer = np.empty((n, 2 * nv, 2 * n_pi))
        regressor, pair, data = pin.computeJointTorqueRegressor, self.pair, self.data
        for i, (qi, vi, ai) in enumerate(zip(Q, V, A, strict=True)):
            R[i] = regressor(pair, data, qi, vi, ai)
        return np.matmul(R[:, :nv, :n_pi] - R[:, nv:, n_pi:], self.P)


REGRESSOR_BY_RUN_COLUMNS = 12
"""From this many columns of the parameter map on, the batch regressor is computed run by
run (:class:`_RegressorByRun`) instead of from 2 RNEA per column (:class:`_Regressor`)."""


class _Probe:
    """Random states and the model terms of several models there (to analyse columns)."""

    def __init__(self, nv: int, count: int = 8) -> None:
        rng = np.random.default_rng(0)
        self.q, self.v, self.w, self.a = (rng.uniform(-2.0, 2.0, (count, nv)) for _ in range(4))
        self.nv, self.count = nv, count

    def evaluate(self, models: Sequence[pin.Model]) -> list[np.ndarray]:
        terms = _PolarisedTerms(models, 1, self.count)
        return [t.copy() for t in terms(self.q, self.v, self.w, self.a)]

    def constant_matrix(self, y: np.ndarray) -> np.ndarray | None:
        """``C`` if ``y = a Cᵀ`` at every probe state (to 1e-10 relative), else None."""
        C, *_ = np.linalg.lstsq(self.a, y, rcond=None)
        return C.T if _close(self.a @ C, y) else None


def _close(a: np.ndarray, b: np.ndarray) -> bool:
    scale = max(1.0, float(np.abs(b).max()), float(np.abs(a).max()))
    return bool(np.abs(a - b).max() <= 1e-10 * scale)


class BatchTerms(RigidBodyTermsMixin):
    """:class:`~twolink_pin.controllers.Terms` for N runs advanced together."""

    def __init__(self, controller: Controller, runs: int, threads: int) -> None:
        check_parallel()
        robot = controller.robot
        self._nv = robot.nv
        self._runs = runs
        self._threads = threads
        self._model = robot.model
        self._map = robot.parameter_map
        self._regressor: _Regressor | _RegressorByRun | None = None
        p = controller.model_parameters
        self._rigid = RigidBodyTerms(robot, p)
        self._p_rows: np.ndarray | None = None
        self._shared: _PolarisedTerms | None = None
        if p is not None and p.ndim == 2 and p.shape[0] > 1:
            if p.shape[0] != runs:
                raise InvalidParameterError(
                    "model_parameters", f"shape {p.shape}", f"one row per run ({runs}) or one row for all"
                )
            self._p_rows = np.ascontiguousarray(p)
        else:
            model = robot.model if p is None else model_with_parameters(robot.model, self._map, p.reshape(-1))
            self._shared = _PolarisedTerms([model], threads, runs)

    def _columns(self) -> _Regressor | _RegressorByRun:
        if self._regressor is None:
            if self._map.matrix.shape[1] >= REGRESSOR_BY_RUN_COLUMNS:
                self._regressor = _RegressorByRun(self._model, self._map)
            else:
                self._regressor = _Regressor(self._model, self._map, self._threads, self._runs)
        return self._regressor

    def model(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        shape = (self._runs, self._nv)
        q, v, w = _rows(q, shape), _rows(v, shape), _rows(w, shape)
        if self._shared is not None:
            return frozen(self._shared(q, v, w, a)[0])
        assert self._p_rows is not None
        columns = self._columns()(q, v, w, a)
        p = self._p_rows
        tau = columns[0] * p[:, 0:1]
        for j in range(1, len(columns)):
            tau = tau + columns[j] * p[:, j : j + 1]
        return frozen(tau)

    def regressor(self, q: np.ndarray, v: np.ndarray, w: np.ndarray, a: np.ndarray) -> np.ndarray:
        shape = (self._runs, self._nv)
        q, v, w = _rows(q, shape), _rows(v, shape), _rows(w, shape)
        columns = self._columns()
        if isinstance(columns, _RegressorByRun):
            return frozen(columns.matrix(q, v, w, a))
        return frozen(np.stack(columns(q, v, w, a), axis=2))

    def friction_regressor(self, v: np.ndarray, smoothing: float = 0.0) -> np.ndarray:
        return frozen(friction_regressor(np.broadcast_to(v, (self._runs, self._nv)), smoothing))


def terms_for(
    controller: Controller, runs: int = 1, threads: int | None = None
) -> SingleRunTerms | BatchTerms:
    """The terms the engine passes to ``controller.compute`` for ``runs`` runs.

    Args:
        controller: The law (its robot and, if any, its ``model_parameters``).
        runs: N, the number of runs evaluated together.
        threads: Threads for Pinocchio's parallel algorithms (N > 1); default all cores,
            at most one per :data:`MIN_RUNS_PER_THREAD` runs.
    """
    if not (isinstance(runs, int) and runs >= 1):
        raise InvalidParameterError("runs", runs, "a whole number >= 1")
    p = controller.model_parameters
    if runs == 1:
        if p is not None and p.ndim == 2 and p.shape[0] != 1:
            raise InvalidParameterError("model_parameters", f"shape {p.shape}", "one row for a single run")
        return SingleRunTerms(controller)
    return BatchTerms(controller, runs, threads_for(runs, threads))
