"""Exceptions of twolink-pin.

Every error the package raises on bad input derives from :class:`TwolinkPinError`.
Each subclass keeps the offending value(s) as attributes and its message says what was
expected, so a caller can both show it and act on it. The CLI turns any of them into one
line on stderr: exit status 2 for bad input, 1 for a run that failed
(:class:`SimulationDivergedError`, :class:`ControllerError`, :class:`OptimizationError`).

Every exception pickles with its attributes (``__reduce__``), so an error raised in a
worker process (the report's pool, a Dask worker) arrives whole in the parent.
"""

from __future__ import annotations

from typing import Any


class TwolinkPinError(Exception):
    """Base class of every error twolink-pin raises on bad input or a failed run."""

    _fields: tuple[str, ...] = ()

    def __reduce__(self) -> str | tuple[Any, ...]:
        if not self._fields:
            return super().__reduce__()
        return (type(self), tuple(getattr(self, name) for name in self._fields))


class InvalidURDFError(TwolinkPinError):
    """A robot description that cannot give a sound model.

    Attributes:
        path: The URDF file (or ``"<string>"`` for XML given as text).
        element: The offending element, e.g. ``link 'link2' <mass>``.
        reason: What is wrong and what was expected.
    """

    _fields = ("path", "element", "reason")

    def __init__(self, path: str, element: str, reason: str) -> None:
        self.path = path
        self.element = element
        self.reason = reason
        super().__init__(f"{path}: {element}: {reason}")


class InvalidParameterError(TwolinkPinError, ValueError):
    """A configuration value outside its valid range.

    Attributes:
        name: The parameter's name.
        value: The value received.
        expected: A description of the valid values.
    """

    _fields = ("name", "value", "expected")

    def __init__(self, name: str, value: Any, expected: str) -> None:
        self.name = name
        self.value = value
        self.expected = expected
        super().__init__(f"{name} = {value!r} is invalid: expected {expected}")


class UnreachableTargetError(TwolinkPinError, ValueError):
    """An end-effector target outside the reachable workspace.

    Attributes:
        target: The target (x, y) [m].
        r_min: Inner radius of the reachable annulus [m].
        r_max: Outer radius of the reachable annulus [m].
    """

    _fields = ("target", "r_min", "r_max")

    def __init__(self, target: tuple[float, float], r_min: float, r_max: float) -> None:
        self.target = target
        self.r_min = r_min
        self.r_max = r_max
        x, y = target
        r = float((x * x + y * y) ** 0.5)
        digits = 4  # enough digits that r and the radius it crosses print differently
        while digits < 17 and any(f"{r:.{digits}g}" == f"{bound:.{digits}g}" for bound in (r_min, r_max)):
            digits += 1
        super().__init__(
            f"target ({x:.{digits}g}, {y:.{digits}g}) m is outside the reachable annulus "
            f"{r_min:.{digits}g} <= r <= {r_max:.{digits}g} m (r = {r:.{digits}g} m)"
        )


class InverseKinematicsError(TwolinkPinError, ValueError):
    """A Cartesian target the numerical inverse kinematics did not reach, or reached only
    at a singular configuration.

    Attributes:
        target: The target position [m] (2 or 3 coordinates).
        reason: What went wrong (closest distance reached, or the singular value).
        q: The configuration the solver stopped at [rad].
    """

    _fields = ("target", "reason", "q")

    def __init__(self, target: tuple[float, ...], reason: str, q: tuple[float, ...]) -> None:
        self.target = target
        self.reason = reason
        self.q = q
        point = ", ".join(f"{c:.4g}" for c in target)
        super().__init__(f"end-effector target ({point}) m: {reason}")


class SimulationDivergedError(TwolinkPinError):
    """A closed-loop run whose state became non-finite or absurd.

    Attributes:
        controller: The controller's name.
        time: Simulation time [s] at which divergence was detected.
        detail: What was detected.
    """

    _fields = ("controller", "time", "detail")

    def __init__(self, controller: str, time: float, detail: str) -> None:
        self.controller = controller
        self.time = time
        self.detail = detail
        super().__init__(f"simulation with controller '{controller}' diverged at t = {time:.6g} s: {detail}")


class ControllerError(TwolinkPinError):
    """A control law that raised, or returned something other than it must, during a run.

    Attributes:
        controller: The law's name.
        time: Simulated time [s] of the evaluation (NaN where it is not known).
        detail: What went wrong (the law's own exception, or the bad shape).
    """

    _fields = ("controller", "time", "detail")

    def __init__(self, controller: str, time: float, detail: str) -> None:
        self.controller = controller
        self.time = time
        self.detail = detail
        at = f" at t = {time:.6g} s" if time == time else ""  # NaN: the time is not known (a Dask task)
        super().__init__(f"controller '{controller}' failed{at}: {detail}")


class OptimizationError(TwolinkPinError):
    """An optimisation that did not reach an answer: its constraints cannot all hold, or its
    solver stopped before converging. A failed run (exit status 1), not bad input.

    Attributes:
        problem: What was being solved, in words.
        reason: Why it stopped (the constraint that cannot hold, the solver's status, the
            remaining violation).
        iterations: Iterations done.
    """

    _fields = ("problem", "reason", "iterations")

    def __init__(self, problem: str, reason: str, iterations: int) -> None:
        self.problem = problem
        self.reason = reason
        self.iterations = iterations
        super().__init__(f"{problem} failed after {iterations} iterations: {reason}")


class ControllerSpecError(TwolinkPinError):
    """A reference to a control law (``name``, ``file.py:Class``, ``module:Class``) that
    does not lead to one.

    Attributes:
        spec: The reference as given.
        reason: What is wrong and what was expected.
    """

    _fields = ("spec", "reason")

    def __init__(self, spec: str, reason: str) -> None:
        self.spec = spec
        self.reason = reason
        super().__init__(f"controller {spec!r}: {reason}")


class InputFileError(TwolinkPinError):
    """An input file that cannot be read safely (missing, not a regular file, too large).

    Attributes:
        path: The offending path.
        reason: What is wrong and what was expected.
    """

    _fields = ("path", "reason")

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class OutputError(TwolinkPinError):
    """An output location that cannot be written safely.

    Attributes:
        path: The offending path.
        reason: Why it cannot be used.
    """

    _fields = ("path", "reason")

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class EquationsError(TwolinkPinError):
    """An arm whose equations of motion the symbolic derivation does not give: a joint it does
    not handle (planar, floating, spherical), a closed chain, more joints than it derives in
    the time it states, or a derivation stopped by ``--timeout`` (bad input: exit status 2).

    Attributes:
        robot: The robot (catalog name or URDF path).
        reason: Which part of the arm, why, and what was expected.
    """

    _fields = ("robot", "reason")

    def __init__(self, robot: str, reason: str) -> None:
        self.robot = robot
        self.reason = reason
        super().__init__(f"{robot}: {reason}")


def raised_at(exc: BaseException, law: object = None) -> str:
    """`` (raised at FILE:LINE in FUNCTION)`` for ``exc``: the innermost frame of the file that
    defines ``law``'s class (a user's law: the line to look at), else the innermost frame; ``""``
    without a traceback."""
    import inspect
    import traceback

    frames = traceback.extract_tb(exc.__traceback__)
    if not frames:
        return ""
    frame = frames[-1]
    if law is not None:
        try:
            source = inspect.getfile(type(law))
        except (TypeError, OSError):
            source = ""
        mine = [f for f in frames if source and f.filename == source]
        frame = mine[-1] if mine else frame
    return f" (raised at {frame.filename}:{frame.lineno} in {frame.name})"


def require_type(value: Any, kind: type | tuple[type, ...], name: str, expected: str) -> None:
    """Raise :class:`InvalidParameterError` naming ``name`` unless ``value`` is a ``kind``:
    ``robot = 'str' is invalid: expected a RobotModel (twolink_pin.load_robot)``. For the
    public functions' arguments, so a wrong type is named, not an ``AttributeError`` deep inside."""
    if not isinstance(value, kind):
        raise InvalidParameterError(name, type(value).__name__, expected)
