"""The one door through which the engine calls a law's ``compute`` (and ``update``): user code contained.

:func:`contained` wraps ``controller.compute`` so that what a law does wrong is an error
naming the law, never a changed simulation or a silent exit:

* its input arrays reach it **read-only**: ``q``, ``v``, ``z`` here (flagged in place: the
  caller passes arrays it will not write into), the reference
  ``q_des``, ``v_des``, ``a_des`` (which later steps share) where the engine samples it
  (:func:`read_only`); a write raises, and the resulting
  :class:`~twolink_pin.errors.ControllerError` says that the inputs are read-only;
* ``sys.exit()`` inside ``compute`` (``SystemExit``) is an error naming the law, not an exit
  of the program with a status the law chose;
* ``MemoryError`` inside ``compute`` names the law (it is the law's allocation, not a bug of
  twolink-pin);
* each run starts from the command's working directory and NumPy global state
  (:func:`~twolink_pin.user_code.restore_baseline`): a law that changed them in an earlier
  run cannot change this one. Importing and building a law are contained by
  :func:`~twolink_pin.user_code.guarded`.

What comes out of the door is checked too (:func:`check_output`, at a law's first
evaluation): a :class:`~twolink_pin.controllers.LawOutput` of the right shapes and of real
numbers.

``os._exit()`` is contained while the CLI runs a command (:func:`~twolink_pin.user_code.exits_contained`:
it raises there, and is named like ``sys.exit``). What cannot be contained in-process: a crash
in C code, ``os._exit`` in a law's own thread or child, a law that blocks signals. The CLI bounds a law that never returns with ``--timeout`` (``cli``), and
``docs/reliability.md`` says what it does about ``os._exit``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from twolink_pin.controllers import Controller, LawInput, LawOutput
from twolink_pin.errors import ContactError, ControllerError, InvalidParameterError
from twolink_pin.simulation.deadline import PROGRESS
from twolink_pin.user_code import HardExit, restore_baseline

READ_ONLY_HINT = (
    "wrote into an array it was given, which is read-only: its inputs (the engine's state and the "
    "reference shared with later steps) and what Terms returns (mass, gravity, bias, model term, "
    "regressor, frame quantities); copy first, e.g. q = x.q.copy() or M = terms.mass(q).copy()"
)


def read_only(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (views taken from it are read-only too)."""
    view = a.view()
    view.setflags(write=False)
    return view


def contained(controller: Controller, method: str = "compute") -> Callable[[LawInput, Any], Any]:
    """``controller.compute`` (or the law's ``update``, ``method="update"``) behind
    read-only inputs, with ``SystemExit`` and ``MemoryError`` turned into
    :class:`ControllerError` naming the law (see module doc).

    The returned function has the method's signature ``(x, terms) -> LawOutput`` (``update``:
    ``-> z``)."""
    restore_baseline()  # each run starts from the command's working directory and NumPy state
    compute = getattr(controller, method)
    progress = PROGRESS
    name = controller.name

    def call(x: LawInput, terms: Any) -> LawOutput:
        # Frozen in place (one flag each, no view: four times per RK4 step): the engine's
        # stage states are its own temporaries (it copies before it writes into one), the
        # adaptive-step method passes views. The reference is made read-only where the
        # engine samples it (once per block).
        # setflags(False) is setflags(write=False) without keyword parsing (half the cost).
        x[1].setflags(False)  # type: ignore[call-arg]
        x[2].setflags(False)  # type: ignore[call-arg]
        x[3].setflags(False)  # type: ignore[call-arg]
        try:
            out = compute(x, terms)
            progress[0] += 1  # a call that returned: the run is slow, not stalled (deadline.STALL)
            return out
        except SystemExit as exc:  # sys.exit, or os._exit while the CLI contains it (user_code.HardExit)
            how = "os._exit" if isinstance(exc, HardExit) else "sys.exit"
            raise ControllerError(
                name, float(x[0]), f"{method} called {how}({exc.code!r}); a law must return or raise"
            ) from None
        except MemoryError as exc:
            raise ControllerError(
                name,
                float(x[0]),
                f"{method} ran out of memory (MemoryError{': ' + str(exc) if str(exc) else ''})",
            ) from None
        except ValueError as exc:
            if "read-only" in str(exc):
                raise ControllerError(name, float(x[0]), f"{READ_ONLY_HINT} ({exc})") from exc
            raise

    return call


def check_output(controller: Controller, out: object, runs: int, nv: int, nz: int, t: float) -> None:
    """Raise :class:`ControllerError` unless ``out`` (the law's output at ``t`` [s]) is a
    :class:`LawOutput` with ``tau`` of shape (runs, nv) and ``dz`` of shape (runs, nz) (or
    None when nz = 0), both of real numbers."""
    name = controller.name
    if not isinstance(out, LawOutput):
        raise ControllerError(
            name, t, f"compute returned {type(out).__name__}; return LawOutput(tau) or LawOutput(tau, dz)"
        )
    for label, value, width in (("tau", out.tau, nv), ("dz", out.dz, nz)):
        if value is None and label == "dz" and nz == 0:
            continue
        shape = getattr(value, "shape", None)
        if not isinstance(value, np.ndarray) or shape != (runs, width):
            got = f"shape {shape}" if shape is not None else type(value).__name__
            raise ControllerError(name, t, f"LawOutput.{label} must have shape ({runs}, {width}), got {got}")
        if value.dtype.kind not in "fiu":  # complex, bool, str, object: not a torque Pinocchio takes
            raise ControllerError(
                name,
                t,
                f"LawOutput.{label} holds {value.dtype} values; expected real numbers (float64)"
                + (f", e.g. {label}.real if the imaginary part is zero" if value.dtype.kind == "c" else ""),
            )


def check_state(controller: Controller, z: object, runs: int, nz: int, t: float) -> np.ndarray:
    """``z`` (the law's :meth:`~twolink_pin.controllers.Controller.update` at ``t`` [s]) as a
    float array of shape (runs, nz), or :class:`ControllerError` naming the law."""
    shape = getattr(z, "shape", None)
    if not isinstance(z, np.ndarray) or shape != (runs, nz) or z.dtype.kind not in "fiu":
        got = f"shape {shape} of {z.dtype}" if isinstance(z, np.ndarray) else type(z).__name__
        raise ControllerError(
            controller.name,
            t,
            f"update must return the new state z, real numbers of shape ({runs}, {nz}); got {got}",
        )
    return np.array(z, dtype=float)


def law_call(
    controller: Controller, noise: list[np.ndarray] | None, method: str = "compute"
) -> Callable[[Any, Any], Any]:
    """The law's ``method`` as the loop calls it: contained (read-only inputs; ``sys.exit``
    and ``MemoryError`` name it) and, with sensor noise, measuring the state plus ``noise``
    (the list the loop fills with the current step's offsets)."""
    law = contained(controller, method)
    if noise is None:
        return law
    new = tuple.__new__

    def compute(x: LawInput, terms: Any) -> Any:  # the law measures the state + noise
        t, q, v, z, *reference = x
        return law(new(LawInput, (t, q + noise[0], v + noise[1], z, *reference)), terms)

    return compute


def update_steps(controller: Controller, dt: float) -> int | None:
    """Steps between the law's state updates (its :meth:`~twolink_pin.controllers.Controller.update_period`
    over the step ``dt`` [s]), None for a law without.

    Raises:
        InvalidParameterError: the period is not finite, shorter than the step or not a
            multiple of it (to 1e-9 relative), naming the law.
    """
    period = controller.update_period()
    if period is None:
        return None
    try:
        value = float(period)
    except (TypeError, ValueError):  # a law's period that is no number: refused below, naming it
        value = float("nan")
    steps = round(value / dt) if np.isfinite(value) and value > 0 else 0
    if steps < 1 or abs(steps * dt - value) > 1e-9 * value:
        raise InvalidParameterError(
            f"{controller.name}: update period",
            period,
            f"a multiple of the simulation step dt = {dt:g} s (at least one step)",
        )
    return int(steps)


def raised_by(exc: BaseException, compute: Callable[..., object]) -> bool:
    """Whether ``exc`` was raised inside the law (its ``compute`` is on the traceback): never a
    plant's failed contact (:class:`~twolink_pin.errors.ContactError`, raised as the law's force
    sensor reads it)."""
    if isinstance(exc, ContactError):
        return False
    code = getattr(getattr(compute, "__func__", compute), "__code__", None)
    tb = exc.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code is code:
            return True
        tb = tb.tb_next
    return isinstance(exc, ControllerError)


__all__ = ["check_output", "check_state", "contained", "law_call", "raised_by", "read_only", "update_steps"]
