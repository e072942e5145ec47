"""The controls of a law's gains, read from its :class:`~twolink_pin.controllers.Gains`
declaration: what each control sets, its label, range and step (no widget here).

* a scalar gain: one control; one declared a whole multiple of another
  (:attr:`~twolink_pin.controllers.gains.GainSpec.multiple_of`, ``mpc``'s horizon of whole
  knots) steps by that gain's value, from one of it;
* a per-joint (per-axis, per-estimate) gain: one control per component and one that scales
  them all (the gain is component × scale);
* a matrix gain: its diagonal, one control per entry, and an overall scale; its
  off-diagonal terms (a full default, or a full matrix typed or given with ``--gain``) are
  kept from its full value (:func:`matrices_of`) and run with the diagonal the controls
  set; a matrix given as a number ``s`` (``s I``): one control.

Every gain has a box that takes its whole value typed (:func:`parse_typed`: a number,
k numbers, or a matrix's k² numbers row by row) and shows the value that runs
(:func:`format_typed`).

The range is about the default: ``[0, 4 v]`` for a positive or nonnegative gain (0 is
refused by a positive gain: the law's own message is shown), ``[−4|v|, 4|v|]`` for a signed
one; the scale runs over ``[0, 4]``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers.gains import GainSpec, spec_of
from twolink_pin.errors import InvalidParameterError

SCALE_RANGE = (0.0, 4.0, 0.01)
"""Low, high and step of a scale control."""
SPAN = 4.0
"""A gain's control runs up to SPAN × its default."""


class Knob(NamedTuple):
    """One control of a gain."""

    gain: str
    """The gain's field name (as ``twolink-pin controllers`` prints it)."""
    component: int | None
    """The component (0-based) of a per-joint, per-axis or per-estimate gain; None for a
    scalar gain or a scale."""
    scale: bool
    """Whether this control scales every component of ``gain``."""
    label: str
    """What the page shows beside the control, the unit included."""
    low: float
    high: float
    step: float
    value: float
    """The default (the value the run starts from)."""
    hint: str
    """The gain's description."""


def nice_step(value: float) -> float:
    """A round step about 1/100 of ``|value|`` (a power of ten; 0.01 for 0)."""
    if value == 0 or not math.isfinite(value):
        return 0.01
    return float(10.0 ** math.floor(math.log10(abs(value)) - 2))


def _range(value: float, spec: GainSpec) -> tuple[float, float, float]:
    if spec.bound == "fraction":  # 0 < value <= 1: the whole range
        return 0.0, 1.0, min(nice_step(value), 0.01)
    step = nice_step(value)
    top = SPAN * abs(value) if value else 1.0
    top = math.ceil(top / step) * step
    low = -top if spec.bound == "any" else 0.0
    return low, top, step


def _components(value: Any, matrix: bool) -> list[float] | None:
    """The components a control each (None: one control for the whole value)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return None
    if matrix:
        square = array.reshape(-1, array.shape[-1], array.shape[-1])[0]
        return [float(x) for x in np.diag(square)]
    return [float(x) for x in array.reshape(-1)]


def knobs_of(gains_type: Any, values: Mapping[str, Any]) -> list[Knob]:
    """The controls of every gain of ``gains_type`` whose resolved value is in ``values``
    (:func:`~twolink_pin.run_spec.gains_used` of the law built with its defaults)."""
    knobs: list[Knob] = []
    for name, value in values.items():
        if value is None or isinstance(value, (bool, str)):
            continue
        spec = spec_of(gains_type, name)
        unit = f" [{spec.unit}]" if spec.unit else ""
        parts = _components(value, spec.matrix)
        if parts is None:
            low, high, step = _range(float(value), spec)
            unit_step = values.get(spec.multiple_of) if spec.multiple_of else None
            if isinstance(unit_step, float) and unit_step > 0:  # whole multiples (mpc's horizon: whole knots)
                low, step = unit_step, unit_step
                high = max(high, unit_step) // unit_step * unit_step
            knobs.append(Knob(name, None, False, f"{name}{unit}", low, high, step, float(value), spec.doc))
            continue
        what = {"joint": "joint", "axis": "axis", "estimate": "estimate"}.get(spec.per, "entry")
        for i, x in enumerate(parts):
            low, high, step = _range(x, spec)
            label = f"{name} {what} {'xyz'[i] if spec.per == 'axis' and i < 3 else i + 1}{unit}"
            knobs.append(Knob(name, i, False, label, low, high, step, x, spec.doc))
        low, high, step = SCALE_RANGE
        knobs.append(Knob(name, None, True, f"{name} × (all)", low, high, step, 1.0, f"scales every {name}"))
    return knobs


def matrices_of(gains_type: Any, values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The full value ``(k, k)`` of every matrix gain in ``values`` given as a matrix or a
    diagonal (its off-diagonal terms are kept beside the controls of its diagonal)."""
    out: dict[str, np.ndarray] = {}
    for name, value in values.items():
        if value is None or isinstance(value, (bool, str)) or not spec_of(gains_type, name).matrix:
            continue
        array = np.asarray(value, dtype=float)
        if array.ndim == 1:
            out[name] = np.diag(array)
        elif array.ndim >= 2:
            out[name] = np.array(array.reshape(-1, array.shape[-1], array.shape[-1])[0])
    return out


def _matrix_value(matrix: np.ndarray) -> tuple[float, ...]:
    """A matrix gain as the command line takes it: its diagonal (k numbers) when it is
    diagonal, else its k² numbers row by row."""
    if np.count_nonzero(matrix - np.diag(np.diag(matrix))) == 0:
        return tuple(float(x) for x in np.diag(matrix))
    return tuple(float(x) for x in matrix.reshape(-1))


def gains_from(
    knobs: list[Knob], settings: Mapping[int, float], matrices: Mapping[str, np.ndarray] | None = None
) -> dict[str, Any]:
    """The gains the controls ask for: knob position in ``knobs`` → value. A per-component
    gain is its components × its scale (a tuple); a matrix gain in ``matrices`` is that
    matrix with its diagonal set by the controls, × its scale (k numbers when diagonal,
    else k² row by row: off-diagonal terms are never dropped)."""
    parts: dict[str, list[float]] = {}
    scales: dict[str, float] = {}
    gains: dict[str, Any] = {}
    matrices = matrices or {}
    for i, knob in enumerate(knobs):
        value = float(settings.get(i, knob.value))
        if knob.scale:
            scales[knob.gain] = value
        elif knob.component is None:
            gains[knob.gain] = value
        else:
            parts.setdefault(knob.gain, []).append(value)
    for name, values in parts.items():
        scale = scales.get(name, 1.0)
        full = matrices.get(name)
        if full is not None and full.shape == (len(values), len(values)):
            matrix = np.array(full, dtype=float)
            matrix[np.diag_indices(len(values))] = values
            gains[name] = _matrix_value(scale * matrix)
        else:
            gains[name] = tuple(x * scale for x in values)
    return gains


def _text(x: float) -> str:
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def format_typed(value: Any) -> str:
    """A gain's value as its box shows it: ``350``, ``350, 300``, a ``(k, k)`` matrix as its
    rows ``150, 20, 0; 20, 150, 0; 0, 0, 80`` (each number the shortest text that reads back)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return _text(float(array))
    if array.ndim == 2:
        return "; ".join(", ".join(_text(x) for x in row) for row in array)
    return ", ".join(_text(x) for x in array.reshape(-1))


def parse_typed(name: str, text: str, count: int | None, matrix: bool = False) -> float | np.ndarray:
    """A gain's typed value: one number (``count`` None), or ``count`` numbers (one number:
    the same for each), or for a matrix gain also ``count²`` numbers row by row (a
    ``(count, count)`` array). Numbers are separated by commas, spaces or semicolons; brackets
    are ignored; exponent notation is read as typed (``1e308``, ``1e-300``).

    Raises:
        InvalidParameterError: text that is no number, NaN or infinite numbers (a number
            too large for a float is infinite), or a count of numbers that fits no shape.
    """
    cleaned = text.replace("[", " ").replace("]", " ").replace("(", " ").replace(")", " ")
    tokens = [t for t in cleaned.replace(";", " ").replace(",", " ").split() if t]
    if count is None:
        shape = "one number"
    elif matrix:
        shape = f"1, {count} or {count * count} numbers (a number, the diagonal, or the matrix row by row)"
    else:
        shape = f"1 or {count} numbers"
    numbers: list[float] = []
    for token in tokens:
        try:
            x = float(token)
        except ValueError:
            raise InvalidParameterError(name, text, f"{shape}; {token!r} is not a number") from None
        if not math.isfinite(x):
            raise InvalidParameterError(name, text, f"{shape}; {token!r} is not a finite float")
        numbers.append(x)
    if count is None:
        if len(numbers) != 1:
            raise InvalidParameterError(name, text, shape)
        return numbers[0]
    if len(numbers) == 1:
        return np.full(count, numbers[0])
    if len(numbers) == count:
        return np.array(numbers)
    if matrix and len(numbers) == count * count:
        return np.array(numbers).reshape(count, count)
    raise InvalidParameterError(name, text, f"{shape}, got {len(numbers)}")


def knob_changes(old: list[Knob], new: list[Knob]) -> list[str]:
    """What differs between two sets of controls (names, defaults, units): ``[]`` when the
    page's controls still fit the law's ``Gains`` declaration."""
    before = {k.label: k for k in old}
    after = {k.label: k for k in new}
    changes = [f"new control {label!r}" for label in after if label not in before]
    changes += [f"control {label!r} gone" for label in before if label not in after]
    changes += [
        f"{label!r} default {after[label].value:g} (was {before[label].value:g})"
        for label in after
        if label in before and after[label].value != before[label].value
    ]
    return changes


__all__ = [
    "SCALE_RANGE",
    "SPAN",
    "Knob",
    "format_typed",
    "gains_from",
    "knob_changes",
    "knobs_of",
    "matrices_of",
    "nice_step",
    "parse_typed",
]
