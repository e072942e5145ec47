"""Gains of a control law: a frozen dataclass whose fields declare their shape and unit.

A law's gains class subclasses :class:`Gains` and declares each field with :func:`gain`::

    @dataclass(frozen=True, eq=False)
    class SlidingModeGains(Gains):
        k: Any = gain(None, per="joint", unit="N·m·s/rad", doc="sliding gain K")
        lam: Any = gain(5.0, unit="1/s", doc="λ in s = ė + λ e")

``per`` says what one value is for: ``"scalar"`` (one number), ``"joint"`` (one per joint,
or a scalar for all joints) or ``"estimate"`` (one per estimated parameter, or a scalar).
Validation on construction turns every value into a float or a read-only float array and
names the field, the value and what was expected on error: a per-joint or per-estimate
sequence is stored as one row ``(1, k)`` — the same 2-D layout as the laws' ``(N, nv)``
arrays, which keeps numpy on its fast path for N = 1. Any field may also hold one value
**per run** — a leading batch axis, shape ``(N, k)`` (``(N,)`` for a scalar field, stored
as ``(N, 1)``) — so that one law object drives N runs of a batch with N gain sets: the
law's arithmetic broadcasts, it never sees N.

A field declared ``matrix=True`` holds a **matrix** gain (``per`` gives its size k:
``"joint"`` nv, ``"estimate"`` the estimates, ``"axis"`` the 3 world axes): a number s
(``s I``), k numbers (a diagonal), k² numbers (a ``(k, k)`` matrix row by row, as the CLI's
``--gain kp=1500,0,0,0,1500,0,0,0,800`` gives them), a symmetric positive-definite
``(k, k)`` matrix, or one such matrix per run ``(N, k, k)`` (or one number per run,
``(N, 1)``: a sweep's draws) — checked (shape, symmetry to 1e-12 relative, Cholesky; a
refusal names the check and the numbers), and stored as ``(1, k, k)`` or ``(N, k, k)`` once
the law knows k (k or k² numbers of a per-joint or per-estimate gain wait for it: 4 numbers
are a 2 × 2 matrix on a 2-joint arm, a diagonal on a 4-joint one): the law applies it
with ``np.matvec(K, e)``. Text and JSON show a matrix as its rows (:func:`format_gain`,
:func:`gain_as_json`).

A per-joint or per-estimate field may default to ``None``: the law then derives the value
from the robot (its ``scaled_gains``), or the robot's profile supplies one
(:attr:`twolink_pin.model.RobotModel.gain_presets`, e.g. the course report's gains for
the twolink).
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, field, fields
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers.matrix_gains import (
    GAIN_RANGE,
    MATRIX_EXPECTED,
    shape_failed,
    validate_matrix,
)
from twolink_pin.errors import InvalidParameterError

SHAPES = ("scalar", "joint", "estimate", "axis")
"""What one value of a gain is for."""
BOUNDS = ("positive", "nonnegative", "any", "fraction")
"""Sign constraints a gain may declare."""


class GainSpec(NamedTuple):
    """What :func:`gain` records in a field's metadata."""

    per: str
    """One of :data:`SHAPES`."""
    unit: str
    """SI unit of the gain (``""`` for a pure number)."""
    bound: str
    """One of :data:`BOUNDS`."""
    doc: str
    """One-line description."""
    matrix: bool = False
    """A matrix gain (see the module docstring)."""
    choices: tuple[str, ...] = ()
    """A gain that is one word of these (``("relax", "fail")``), not a number: one value for
    every run, given by name (``--gain on_infeasible=fail``); empty for a number."""
    multiple_of: str = ""
    """The name of another gain of the law whose whole multiples this one takes (``mpc``'s
    ``horizon``: whole knot intervals); a tuning control steps by that gain's value."""


def gain(
    default: Any,
    *,
    per: str = "scalar",
    unit: str = "",
    bound: str = "positive",
    doc: str = "",
    matrix: bool = False,
    choices: tuple[str, ...] = (),
    multiple_of: str = "",
) -> Any:
    """A gains field with its default, shape, unit and sign constraint.

    Args:
        default: The default value (a number, a tuple, or ``None`` for per-joint or
            per-estimate gains derived from the robot).
        per: ``"scalar"``, ``"joint"`` or ``"estimate"``.
        unit: SI unit, e.g. ``"N·m/rad"``.
        bound: ``"positive"`` (> 0, default), ``"nonnegative"`` (>= 0), ``"any"`` or
            ``"fraction"`` (0 < value <= 1: a share of something, e.g. of a limit).
        doc: One-line description (shown by the CLI and the report).
        matrix: A symmetric positive-definite matrix gain of size k given by ``per``
            (``"joint"``, ``"estimate"`` or ``"axis"``); ``bound`` is then "positive".
        choices: The words the gain may be (its default one of them): a gain that names a
            behaviour (``on_infeasible = "relax"`` or ``"fail"``) rather than a number; scalar,
            one value for every run.
        multiple_of: Another gain whose whole multiples this one takes (see
            :attr:`GainSpec.multiple_of`; the law enforces it).
    """
    if per not in SHAPES:
        raise ValueError(f"per must be one of {SHAPES}, got {per!r}")
    if bound not in BOUNDS:
        raise ValueError(f"bound must be one of {BOUNDS}, got {bound!r}")
    if default is None and per == "scalar":
        raise ValueError("a scalar gain needs a default value")
    if matrix and (per == "scalar" or bound != "positive"):
        raise ValueError("a matrix gain is per joint, estimate or axis, and positive definite")
    if choices and (per != "scalar" or matrix or default not in choices):
        raise ValueError(
            f"a gain of choices {choices} is scalar and defaults to one of them, got {default!r}"
        )
    if multiple_of and per != "scalar":
        raise ValueError("a gain that is a multiple of another is a scalar gain")
    spec = GainSpec(per, unit, bound, doc, matrix, tuple(choices), multiple_of)
    return field(default=default, metadata={"gain": spec})


def spec_of(gains_type: type[Gains] | Gains, name: str) -> GainSpec:
    """The :class:`GainSpec` of field ``name``."""
    for f in fields(gains_type):
        if f.name == name:
            return gain_spec(f)
    raise KeyError(name)


def gain_spec(f: Any) -> GainSpec:
    spec = f.metadata.get("gain")
    if spec is None:  # a plain dataclass field: a positive scalar without unit
        return GainSpec("scalar", "", "positive", "")
    return spec


def _expected(spec: GainSpec) -> str:
    low, high = GAIN_RANGE
    sign = {
        "positive": f" > 0 (from {low:g} to {high:g})",
        "nonnegative": f" >= 0 (0, or from {low:g} to {high:g})",
        "any": f" within ±{high:g}",
        "fraction": f", a fraction 0 < value <= 1 (from {low:g})",
    }[spec.bound]
    unit = f" [{spec.unit}]" if spec.unit else ""
    return {
        "scalar": f"a finite number{sign}{unit} (or one per run)",
        "joint": f"finite numbers{sign}{unit}: one for every joint or one per joint (or a row per run)",
        "estimate": f"finite numbers{sign}{unit}: one for every estimated parameter or one each (or a row per run)",
        "axis": f"finite numbers{sign}{unit}: one for every axis or one per axis x, y, z (or a row per run)",
    }[spec.per]


def _validate_choice(name: str, value: Any, spec: GainSpec) -> str:
    if isinstance(value, str) and value.strip() in spec.choices:
        return value.strip()
    words = ", ".join(repr(c) for c in spec.choices)
    raise InvalidParameterError(name, value, f"one of {words} (one value for every run)")


def _validate(name: str, value: Any, spec: GainSpec) -> Any:
    if spec.choices:
        return _validate_choice(name, value, spec)
    if value is not None and spec.matrix:
        return validate_matrix(name, value, spec.unit, spec.per)
    if isinstance(value, str):  # a word where a number is expected (--gain kp=abc)
        raise InvalidParameterError(name, value, f"a number, got {value!r}: {_expected(spec)}")
    if value is None:
        if spec.per == "scalar":
            raise InvalidParameterError(name, value, _expected(spec))
        return None
    if isinstance(value, bool):
        raise InvalidParameterError(name, value, _expected(spec))
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, _expected(spec)) from None
    allowed = (0, 1) if spec.per == "scalar" else (0, 1, 2)
    if spec.per == "scalar" and array.ndim == 2 and array.shape[1] == 1:  # validated before: a column
        array = array[:, 0]  # per run (dataclasses.replace validates every field again)
    if array.ndim not in allowed or array.size == 0:
        raise InvalidParameterError(name, value, f"{_expected(spec)} (got shape {array.shape})")
    bad = ~np.isfinite(array)
    with np.errstate(invalid="ignore"):
        bad |= ~(np.abs(array) <= GAIN_RANGE[1])
        if spec.bound == "positive":
            bad |= ~(array >= GAIN_RANGE[0])
        elif spec.bound == "nonnegative":
            bad |= ~((array == 0) | (array >= GAIN_RANGE[0]))
        elif spec.bound == "fraction":
            bad |= ~((array >= GAIN_RANGE[0]) & (array <= 1.0))
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"{name}[{', '.join(map(str, index))}]" if index else name
        raise InvalidParameterError(where, float(array[index]), _expected(spec))
    if array.ndim == 0:
        return float(array)
    if spec.per == "scalar":  # one value per run: a column, so it broadcasts against (N, k)
        array = array.reshape(-1, 1)
    elif array.ndim == 1:  # one row for every run: (1, k), like the laws' (N, nv) arrays
        array = array.reshape(1, -1)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Gains:
    """Base class of every law's gains (see the module docstring)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _validate(f.name, getattr(self, f.name), gain_spec(f)))

    def values(self) -> dict[str, Any]:
        """Field name → value (float, array or None)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def describe(self, digits: int = 4) -> str:
        """``kp = (350, 300) N·m/rad, kd = ...``: every field with its unit; a matrix gain as
        its rows, ``kp = [[1500, 20, 0], [20, 1500, 0], [0, 0, 800]] 1/s²`` (a diagonal one as
        its diagonal)."""
        parts = []
        for f in fields(self):
            value, spec = getattr(self, f.name), gain_spec(f)
            text = "from the robot" if value is None else format_gain(value, digits)
            parts.append(f"{f.name} = {text}{' ' + spec.unit if spec.unit else ''}")
        return ", ".join(parts)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The gains' field names, in order."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Field name → declared default."""
        return {f.name: (None if f.default is MISSING else f.default) for f in fields(cls)}


def gain_as_json(value: Any) -> Any:
    """A gain value JSON-ready: a number, a list (per joint, axis or estimate), a matrix as its
    rows (a list of lists) — a diagonal matrix as its diagonal, k numbers, as ``--gain`` takes
    them (the report's ``K = (90, 90)``) —, one of these per run for per-run values; None stays None."""
    if value is None or isinstance(value, (bool, str)):
        return value
    array = np.asarray(value, dtype=float)
    if array.ndim in (2, 3) and array.shape[0] == 1:  # one row or matrix for every run
        array = array[0]
        if array.ndim == 2 and not np.any(array - np.diag(np.diag(array))):
            array = np.diag(array)
    return float(array) if array.ndim == 0 else array.tolist()


def default_as_json(gains_type: type[Gains], name: str) -> Any:
    """Field ``name``'s declared default JSON-ready (:func:`gain_as_json` of its validated
    value: a matrix default as its rows); None when the robot supplies it."""
    default = {f.name: f.default for f in fields(gains_type)}[name]
    if default is None or default is MISSING:
        return None
    try:
        return gain_as_json(_validate(name, default, spec_of(gains_type, name)))
    except InvalidParameterError:  # a user's law with a bad default: shown as declared
        return repr(default)


MATRIX_ROWS_SHOWN = 3
"""A matrix gain of at most this many rows is shown as its rows; a larger one by its diagonal and
its largest off-diagonal entry (JSON keeps every row)."""


def format_gain(value: Any, digits: int = 4) -> str:
    """A gain value as text: ``350``, ``(350, 300)`` (per joint, or a diagonal matrix), a matrix
    as its rows ``[[1500, 20, 0], [20, 1500, 0], [0, 0, 800]]``; per-run values (N of them)
    shortened."""
    shown = gain_as_json(value)
    if isinstance(shown, str):  # a gain of choices
        return shown
    if isinstance(shown, float):
        return f"{shown:.{digits}g}"
    array = np.asarray(shown, dtype=float)

    def numbers(row: np.ndarray) -> str:
        return ", ".join(f"{x:.{digits}g}" for x in row)

    one_matrix = isinstance(value, np.ndarray) and value.ndim == 3 and value.shape[0] == 1 and array.ndim == 2
    if one_matrix and array.shape[0] > MATRIX_ROWS_SHOWN:  # a 7 × 7 M(q₀)-scaled gain: diagonal, coupling
        k, coupling = array.shape[0], float(np.abs(array - np.diag(np.diag(array))).max())
        return f"{k} × {k} matrix, diagonal ({numbers(np.diag(array))}), off-diagonal up to {coupling:.{digits}g}"
    if one_matrix:
        return "[" + ", ".join(f"[{numbers(row)}]" for row in array) + "]"
    flat = array.ravel()
    text = "(" + numbers(flat[:12]) + (", …)" if flat.size > 12 else ")")
    return text if array.ndim <= 1 else f"{array.shape[0]} runs {text}"


def runs_of(value: Any) -> int | None:
    """The number of runs a validated gain value holds (its leading axis), or None if it
    is the same for every run."""
    if isinstance(value, np.ndarray) and value.ndim in (2, 3) and value.shape[0] > 1:
        return int(value.shape[0])
    return None


def one_row(value: Any, width: int) -> np.ndarray:
    """A single-run gain (a number or a ``(1, k)`` row) as ``width`` values, shape (width,)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 2 and array.shape[0] != 1:
        raise InvalidParameterError("gain", f"shape {array.shape}", "one value set (not one row per run)")
    return np.broadcast_to(array.reshape(-1), (width,)).copy()


def check_count(name: str, value: Any, spec: GainSpec, width: int, what: str) -> None:
    """Refuse a value given as numbers (one value set: a number or a flat sequence) whose count
    the gain cannot take on this robot — before its entries are checked, so that four numbers
    for a two-joint gain are named as four numbers, not by an entry that is out of range.

    Args:
        name: The gain's field name.
        value: The value as given (per-run arrays and matrices are left to the later checks).
        spec: Its declaration (``per``, ``matrix``).
        width: How many values ``per`` means here (nv, the estimates, 3 axes).
        what: What the values are for (``per joint, nv = 2``).

    Raises:
        InvalidParameterError: the count received and the counts expected.
    """
    if spec.per == "scalar" or isinstance(value, (bool, str)) or value is None:
        return
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return  # not numbers: the value's own check says so
    if array.ndim != 1:
        return
    n = array.size
    shown = array.tolist() if n <= 24 else f"{n} numbers"
    if spec.matrix:
        if n not in (1, width, width * width):
            expected = MATRIX_EXPECTED.format(unit=f" [{spec.unit}]" if spec.unit else "")
            raise InvalidParameterError(name, shown, f"{expected}; {shape_failed(n, width)} ({what})")
    elif n not in (1, width):
        raise InvalidParameterError(name, shown, f"1 or {width} numbers ({what}); got {n}")


def check_width(name: str, value: Any, width: int, what: str) -> None:
    """Raise unless ``value`` (validated) is a scalar, ``width`` values, or per run one or
    ``width`` values (shape ``(N, 1)`` or ``(N, width)``)."""
    if value is None or isinstance(value, float):
        return
    if value.ndim == 3:  # a matrix gain
        if value.shape[1:] != (width, width):
            raise InvalidParameterError(
                name, f"matrices of shape {value.shape[1:]}", f"({width}, {width}) matrices ({what})"
            )
        return
    if value.shape[1] not in (1, width):
        rows = value.tolist()
        shown = (rows[0] if len(rows) == 1 else rows) if value.size <= 24 else f"array of shape {value.shape}"
        got = f"{value.shape[1]} numbers" if value.shape[0] == 1 else f"shape {value.shape}"
        raise InvalidParameterError(
            name, shown, f"one value or {width} ({what}), or one row of them per run; got {got}"
        )


def is_finite_number(x: Any) -> bool:
    """Whether ``x`` is an int or float (not a bool) and finite."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
