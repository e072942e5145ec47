"""The engine: N ≥ 1 runs of one law on one plant, advanced together by fixed-step RK4.

State ``x = (q, q̇, z)`` per run (``z``: the law's internal state), arrays ``(N, ·)``.

* **Per-stage law** (default): classical RK4, the law evaluated at every stage, the
  reference sampled on the half-step grid.
* **Sampled law** (``control_period`` = m steps): the law is evaluated once every m steps
  at the state of that instant and its output — τ and ż — held (zero-order hold) until the
  next sample; RK4 integrates the plant under the held torque and ``z ← z + dt ż`` per
  step. This is what a digital controller does; it differs from the per-stage law by
  O(control_period).

* **A law that plans** (:meth:`~twolink_pin.controllers.Controller.update_period`: a model-
  predictive law's replanning period, a multiple of the step): at every multiple of that
  period, before the law's evaluation at that instant, the engine replaces ``z`` by the law's
  :meth:`~twolink_pin.controllers.Controller.update` from the measured state (its new plan);
  in between the law follows the plan in ``z``.

A plant that pushes back (:mod:`twolink_pin.disturbances`: a wrench, a payload step,
sensor noise, a delay) runs in the same loop: :class:`~twolink_pin.simulation.events.PlantEvents`
gives each step's dynamics and the noise on what the law measures, and with a delay the law is
sampled every step (or control period) and a :class:`~twolink_pin.simulation.events.DelayLine`
applies its torque ``delay`` steps late (details in :mod:`twolink_pin.simulation.events`); with
joint stops the state after each step is put back within the position ranges
(:mod:`twolink_pin.simulation.stops`).

The law gets its Pinocchio terms from :func:`~twolink_pin.simulation.terms.terms_for`
and the plant's accelerations come from :func:`~twolink_pin.simulation.forward.dynamics_for`
(one ABA per run and stage). Output samples are written block by block (:data:`BLOCK`
steps): into the full record when ``record=True``, else into a small buffer handed to an
observer (e.g. running metrics) — memory then stays O(N), whatever the duration.

After every block each run's state is checked: a run whose state is non-finite or beyond
:data:`~twolink_pin.simulation.config.DIVERGENCE_LIMIT` has diverged at the first such
sample; so has a run whose law returned a non-finite torque. With ``stop_on_divergence``
(single runs) that raises; otherwise the run is parked on the reference and flagged in
:attr:`EngineRun.diverged_at` while the others go on. A law that raises, or returns the
wrong type or shape, stops the run with :class:`~twolink_pin.errors.ControllerError`
naming the law and the simulated time.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers import Controller, LawInput
from twolink_pin.errors import ControllerError, TwolinkPinError, raised_at
from twolink_pin.plant import Plant
from twolink_pin.simulation.config import SimulationConfig
from twolink_pin.simulation.containment import (
    check_output,
    check_state,
    law_call,
    raised_by,
    read_only,
    update_steps,
)
from twolink_pin.simulation.deadline import bounded, run_watcher, timed_out
from twolink_pin.simulation.divergence import flag_block, late_divergence, law_reason
from twolink_pin.simulation.events import DelayLine, PlantEvents
from twolink_pin.simulation.forward import dynamics_for
from twolink_pin.simulation.preview import preview_offsets
from twolink_pin.simulation.rk4 import Clock, Steps, held_rk4, stage_step
from twolink_pin.simulation.samples import Observer, Outputs, Samples
from twolink_pin.simulation.sensing import ForceSensor
from twolink_pin.simulation.task_reference import reference_rows
from twolink_pin.simulation.terms import terms_for
from twolink_pin.trajectory import ForceReference, Trajectory

BLOCK = 128
"""Steps per block: how often states are checked and unrecorded samples handed on."""


class EngineRun(NamedTuple):
    """What :func:`integrate` returns."""

    t: np.ndarray
    """Output times [s], shape (K,)."""
    record: Samples | None
    """Every sample (``record=True``), else None."""
    z_final: np.ndarray
    """The law's state at the end, shape (N, nz) (diverged runs: their parked state)."""
    diverged_at: np.ndarray
    """Time [s] each run diverged, NaN if it did not, shape (N,)."""
    detail: tuple[str | None, ...]
    """What was detected for each diverged run, None for the others."""


def integrate(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
    *,
    record: bool,
    observer: Observer | None = None,
    threads: int | None = None,
    stop_on_divergence: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> EngineRun:
    """Advance N runs of ``controller`` on ``plant`` along ``trajectory`` (see module doc).

    Args:
        controller: The law (one object for all runs; its per-run gains broadcast).
        plant: The arm all runs drive.
        trajectory: The reference.
        config: Duration, step, control period (``method`` is not used: RK4).
        q0: Initial positions [rad], shape (N, nv).
        v0: Initial velocities [rad/s], shape (N, nv).
        z0: Initial law state, shape (N, nz).
        record: Keep every sample (:attr:`EngineRun.record`).
        observer: Receives each block of samples.
        threads: Threads for Pinocchio's parallel algorithms (N > 1).
        stop_on_divergence: Raise :class:`SimulationDivergedError` at the first diverged
            run instead of parking it.
        progress: Called as ``progress(steps_done, steps_total)`` after each block.
    """
    run = _Run(controller, plant, config, q0, v0, z0, record, threads, trajectory.force_reference)
    n, dt, clock, events = run.n, run.dt, run.clock, run.events
    ahead = preview_offsets(controller)  # the reference the law asks for ahead of now, or None
    watcher = run_watcher()
    # A diverging run overflows before its block is checked. The run is bounded in wall-clock
    # time (--timeout, simulation.deadline): past it, an error naming the law at t = now.
    with (
        np.errstate(all="ignore"),
        bounded(lambda timeout: timed_out(controller, clock.now, timeout), stall=True),
    ):
        for k0, k1, rq, rv, ra, ref in _block_references(
            controller, trajectory, run.total, n, dt, run.sensor, ahead, run.update_every
        ):
            if events is not None:
                events.draw(k0, k1)
            run.advance(k0, k1, ref)
            run.out.reference(run.rows(k0, k1), rq, rv, ra)
            run.check(k0, k1, rq, rv, stop_on_divergence)
            if observer is not None or watcher is not None:
                block = run.out.block(k0, run.times[k0:k1], run.rows(k0, k1))
                if observer is not None:
                    observer.add(block)
                if watcher is not None:  # simulation.deadline.watched: may raise RunCancelled
                    watcher(block)
            if progress is not None:
                progress(min(k1, n), n)
    recorded = run.out.everything(run.times) if record else None
    return EngineRun(run.times, recorded, run.z, run.diverged_at, tuple(run.detail))


class _Run:
    """One call of :func:`integrate`: what is fixed for the run (the law as the loop calls it,
    the plant's events, the step's factors, the output buffers) and what is carried from block
    to block (the state, the law's held output, the runs still alive and how the others ended)."""

    def __init__(
        self,
        controller: Controller,
        plant: Plant,
        config: SimulationConfig,
        q0: np.ndarray,
        v0: np.ndarray,
        z0: np.ndarray,
        record: bool,
        threads: int | None,
        force_reference: ForceReference | None = None,
    ) -> None:
        self.controller = controller
        self.runs, self.nv = runs, nv = q0.shape
        self.nz = nz = z0.shape[1]
        self.n = n = config.steps
        self.dt = dt = config.duration / n
        hold = config.hold_steps
        self.record = record
        self.terms = terms_for(controller, runs, threads)
        # A plant that pushes back (wrench, payload step, sensor noise, delay, contact): its events
        # choose the dynamics of each step, offset what the law measures, delay its torque.
        self.events = events = PlantEvents(plant, runs, threads, nv, dt) if plant.has_events else None
        contact = None if events is None else events.contact
        self.sensor = (
            None
            if events is None or contact is None
            else ForceSensor(contact, force_reference, events.force_noise)
        )
        self.line = line = DelayLine(plant.delay) if plant.delay > 0 else None
        self.stop = events.stop if events is not None and events.stops is not None else None
        self.accel = dynamics_for(plant, runs, threads) if events is None else events.accel_at(0.0)
        noisy = events is not None and events.noise is not None
        self.noise: list[np.ndarray] = []  # the current step's offsets on (q, q̇) with sensor noise
        self.compute = self.sensed(law_call(controller, self.noise if noisy else None))
        # the configured step, as for the control period: a duration that is not a whole number of
        # steps stretches each step a little (dt above) and the period counts steps alike
        self.update_every = update_steps(controller, config.dt)
        self.update = (
            None
            if self.update_every is None
            else self.sensed(law_call(controller, self.noise if noisy else None, "update"))
        )
        # the law evaluated once per step or period: sampled, delayed, or a plant whose own
        # integrator steps it (MuJoCo's Euler and implicitfast evaluate their forces once per step)
        self.sampled = hold is not None or line is not None or not plant.law_per_stage
        # the plant's own cause of a failed run (MuJoCo's warnings), beside the state's
        self.plant_why = events.failure if events is not None else getattr(self.accel, "failure", None)
        self.every = hold if hold is not None else 1
        self.total = total = n + 1
        felt = record and self.sensor is not None and noisy and plant.sensor_noise.sigma_f > 0  # type: ignore[union-attr]
        size = total if record else min(total, BLOCK)
        self.out = Outputs.empty(size, runs, nv, nz, record and noisy, contact is not None, felt)
        self.times = np.arange(total) * dt
        self.diverged_at = np.full(runs, np.nan)
        self.detail: list[str | None] = [None] * runs
        self.alive = np.ones(runs, dtype=bool)
        self.z_start = np.array(z0, dtype=float)
        self.q, self.v, self.z = np.array(q0, dtype=float), np.array(v0, dtype=float), self.z_start.copy()
        if self.stop is not None:  # a joint that starts beyond its stop starts on it
            self.q, self.v = self.stop(0.0, self.q, self.v)
        if events is not None:  # none starts inside a surface
            events.check_start(self.q)
        self.steps = Steps.of(dt)
        self.no_state = np.zeros((runs, 0))
        # The law's outputs: dz is an (N, nz) array whenever nz > 0 (checked at the first evaluation).
        self.tau1: Any = None
        self.dz1: Any = None
        self.first = True
        self.clock = Clock()  # time of the law evaluation under way (for error messages)

    def sensed(self, law: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
        """``law`` with the force sensor's reading in ``LawInput.contact`` (a scene), else itself."""
        return law if self.sensor is None else self.sensor.wrap(law)

    def rows(self, k0: int, k1: int) -> slice:
        """The buffer rows of samples ``k0 … k1 − 1``."""
        off = 0 if self.record else k0
        return slice(k0 - off, k1 - off)

    def advance(self, k0: int, k1: int, ref: Any) -> None:
        """Steps ``k0 … k1 − 1``: write each sample, evaluate the law where the run samples it
        (``ref[i]``: the law's reference rows of the block's half-step i), advance the state."""
        controller, compute, terms, clock, events, line, noise, stop = (
            self.controller,
            self.compute,
            self.terms,
            self.clock,
            self.events,
            self.line,
            self.noise,
            self.stop,
        )
        runs, nv, nz, n, dt, every, sampled, steps, no_state = (
            self.runs,
            self.nv,
            self.nz,
            self.n,
            self.dt,
            self.every,
            self.sampled,
            self.steps,
            self.no_state,
        )
        Q, V, T, Z, MQ, MV = self.out.Q, self.out.V, self.out.T, self.out.Z, self.out.MQ, self.out.MV
        q, v, z, accel, tau1, dz1, first = self.q, self.v, self.z, self.accel, self.tau1, self.dz1, self.first
        update, update_every, touched = self.update, self.update_every or 1, self.sensor is not None
        # LawInput(...) through tuple.__new__: the NamedTuple's own __new__ is a Python
        # function that costs twice as much, four times a step.
        new = tuple.__new__
        off = 0 if self.record else k0
        filled = k0 - off
        try:
            for k in range(k0, k1):
                i = 2 * (k - k0)
                t = k * dt
                if events is not None:
                    accel = events.accel_at(t)
                    if events.noise is not None:
                        noise[:] = events.noise_at(k)
                if update is not None and k % update_every == 0:  # a planning law replans
                    clock.now = t
                    z = check_state(
                        controller, update(new(LawInput, (t, q, v, z, *ref[i])), terms), runs, nz, t
                    )
                if not sampled or k % every == 0:
                    clock.now = t
                    out = compute(new(LawInput, (t, q, v, z, *ref[i])), terms)
                    if first:
                        check_output(controller, out, runs, nv, nz, t)
                        first = False
                    tau1, dz1 = out.tau, (out.dz if nz else no_state)
                    if line is not None:
                        line.push(k, tau1, dz1)
                tau_k, dz_k = (tau1, dz1) if line is None else line.at(k)  # the torque applied
                b = k - off
                Q[b], V[b], T[b] = q, v, tau_k
                if MQ is not None and MV is not None:
                    MQ[b], MV[b] = q + noise[0], v + noise[1]  # as the law measured it
                if touched:  # a scene: the contact at this sample
                    self.record_contact(b, q, v)
                if nz:
                    Z[b] = z
                filled = b + 1
                if k == n:
                    break
                if sampled:  # zero-order hold (or delay): τ and ż fixed over the step
                    q, v, z = getattr(accel, "held_step", held_rk4(accel))(q, v, z, tau_k, dz_k, steps, nz)
                else:
                    q, v, z = stage_step(
                        compute, terms, accel, q, v, z, tau_k, dz_k, ref, i, t, steps, nz, clock
                    )
                if stop is not None:  # joint stops: back within the ranges
                    q, v = stop(t, q, v)
        except (KeyboardInterrupt, SystemExit, MemoryError):
            raise
        except Exception as exc:
            self.failed(exc, k0 - off, filled, off)
            raise
        self.q, self.v, self.z, self.accel, self.tau1, self.dz1, self.first = q, v, z, accel, tau1, dz1, first

    def record_contact(self, b: int, q: np.ndarray, v: np.ndarray) -> None:
        """Write the contact at sample row ``b`` (state ``q``, ``v``): its wrench, penetration and,
        with force noise, what the sensor read."""
        sensor, out = self.sensor, self.out
        assert sensor is not None and out.W is not None and out.P is not None
        forces = sensor.contact(q, v)  # the law's sensor asked at this state already: kept
        out.W[b], out.P[b] = forces.wrench, forces.penetration
        if out.MW is not None:
            out.MW[b] = sensor.measure(q, v)

    def failed(self, exc: Exception, start: int, filled: int, off: int) -> None:
        """An exception raised inside the law (its ``compute`` or ``update``) as a
        :class:`ControllerError` naming it and the time, after flagging the runs that had
        already diverged in buffer rows ``start:filled`` (a law may raise on a diverged state:
        the divergence is reported). Returns for any other exception: the caller re-raises it."""
        update = self.update
        if not (raised_by(exc, self.compute) or (update is not None and raised_by(exc, update))):
            return
        self.flag(start, filled, off, True)
        if isinstance(exc, ControllerError):
            return
        what = str(exc) if isinstance(exc, TwolinkPinError) else f"{type(exc).__name__}: {exc}"
        controller = self.controller
        raise ControllerError(controller.name, self.clock.now, what + raised_at(exc, controller)) from exc

    def flag(self, start: int, stop: int, off: int, raise_now: bool) -> np.ndarray:
        """Flag the live runs that diverged within buffer rows ``start:stop`` (the first is
        sample ``start + off``); returns them."""
        o = self.out
        return flag_block(
            o.Q, o.V, o.Z, o.T, start, stop, self.times, off,
            self.alive, self.diverged_at, self.detail, self.controller.name, raise_now,
            law_reason(self.controller), self.plant_why,
        )  # fmt: skip

    def check(self, k0: int, k1: int, rq: np.ndarray, rv: np.ndarray, stop_on_divergence: bool) -> None:
        """After steps ``k0 … k1 − 1``: flag the runs that diverged within them or at sample
        ``k1``, and park those on the reference (``rq``, ``rv``: the block's half-step rows)
        while the others go on."""
        rows = self.rows(k0, k1)
        newly = self.flag(rows.start, rows.stop, k0 - rows.start, stop_on_divergence)
        if k1 <= self.n:  # the state after the block's last step is sample k1
            q, v, z = self.q, self.v, self.z
            name = self.controller.name
            newly |= late_divergence(
                q, v, z, self.alive, k1 * self.dt, self.diverged_at, self.detail, name, stop_on_divergence,
                law_reason(self.controller), self.plant_why,
            )  # fmt: skip
            if newly.any():  # park them on the reference, keep the batch going
                j = 2 * (k1 - k0)
                q, v, z = q.copy(), v.copy(), z.copy()  # the law saw them read-only
                q[newly], v[newly], z[newly] = rq[j][0], rv[j][0], self.z_start[newly]
                self.q, self.v, self.z = q, v, z


REFERENCE_BLOCKS = 8
"""Blocks whose reference is sampled in one call: a trajectory's ``sample`` costs a fixed ~75 µs
per call besides ~0.1 µs per time (the twolink's polynomials), 2 µs per step of a single run at one
block per call; eight blocks per call save most of it, and the memory stays O(:data:`BLOCK`)."""


def _block_references(
    controller: Controller,
    trajectory: Trajectory,
    total: int,
    n: int,
    dt: float,
    sensor: ForceSensor | None = None,
    ahead: np.ndarray | None = None,
    update_every: int | None = None,
) -> Iterator[tuple[int, int, np.ndarray, np.ndarray, np.ndarray, Any]]:
    """Per block of samples ``k0 … k1 − 1`` (of ``total``): ``k0``, ``k1`` and its reference as
    :func:`_block_reference` gives it, sampled :data:`REFERENCE_BLOCKS` blocks at a time (every
    quantity is a function of its own time: the same values, element by element)."""
    chunk = BLOCK * REFERENCE_BLOCKS
    for c0 in range(0, total, chunk):
        c1 = min(c0 + chunk, total)
        rq, rv, ra, ref = _block_reference(controller, trajectory, c0, c1, n, dt, sensor, ahead, update_every)
        for k0 in range(c0, c1, BLOCK):
            k1 = min(k0 + BLOCK, c1)
            rows = slice(2 * (k0 - c0), 2 * (k1 - c0) + 1)  # half-steps 2 k0 … min(2 k1, 2 n)
            yield k0, k1, rq[rows], rv[rows], ra[rows], ref[rows]


def _block_reference(
    controller: Controller,
    trajectory: Trajectory,
    k0: int,
    k1: int,
    n: int,
    dt: float,
    sensor: ForceSensor | None = None,
    ahead: np.ndarray | None = None,
    update_every: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Any]:
    """The reference of steps ``k0 … k1 − 1`` on the half-step grid: ``q_des``, ``q̇_des``,
    ``q̈_des`` as read-only (H, 1, nv) rows and the law's input rows (task fields included, the
    force reference's with a ``sensor``, and the preview at the offsets ``ahead`` [s]: at every
    half step, or for a law that plans every ``update_every`` steps at its update instants only)."""
    last_half = min(2 * k1, 2 * n)  # the last stage of step k1 - 1 is at half-step 2 k1
    halves = np.arange(2 * k0, last_half + 1)
    half_t = halves * (dt / 2)
    at = None if update_every is None else (halves % (2 * update_every) == 0)
    half = trajectory.sample(half_t)
    # Shared with later steps: the law can't write. C-contiguous rows: a trajectory may
    # sample column-major, and a strided (1, nv) row takes numpy's slow broadcasting
    # path in every operation of the law and the Terms that touches it.
    rq, rv, ra = (read_only(np.ascontiguousarray(x)[:, None, :]) for x in (half.q, half.v, half.a))
    contact = None if sensor is None else sensor.rows(half_t)
    return rq, rv, ra, reference_rows(controller, trajectory, half_t, half, rq, rv, ra, contact, ahead, at)
