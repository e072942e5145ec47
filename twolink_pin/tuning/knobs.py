"""The controls of a law's gains, read from its :class:`~twolink_pin.controllers.Gains`
declaration: what each control sets, its label, range and step (no widget here).

* a scalar gain: one control;
* a per-joint (per-axis, per-estimate) gain: one control per component and one that scales
  them all (the gain is component × scale);
* a matrix gain: its diagonal, one control per entry, and an overall scale; its
  off-diagonal terms (a full default, or a full matrix typed or given with ``--gain``) are
  kept from its full value (:func:`matrices_of`) and run with the diagonal the controls
  set; a matrix given as a number ``s`` (``s I``): one control.

Every gain has a box that takes its whole value typed (:func:`parse_typed`: a number,
k numbers, or a matrix's k² numbers row by row) and shows the value that runs to the digits
that matter (:func:`format_typed`; the value itself runs with every digit).

The range is about the default: ``[0, 4 v]`` for a positive or nonnegative gain (0 is
refused by a positive gain: the law's own message is shown), ``[−4|v|, 4|v|]`` for a signed
one, ``[0, 1]`` for a fraction; the scale runs over ``[0, 4]``. How a value steps (a key
press, a drag) is the control's :class:`~twolink_pin.tuning.steps.Rule`: the logarithmic grid
for a positive gain and a scale, a whole multiple of another gain for a gain declared so
(``multiple_of``: mpc's horizon in knots), linear otherwise (:mod:`.steps`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.controllers.gains import GainSpec, spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.steps import FRACTION_STEP, SIGNED_SHARE, Rule, grid_nearest, shown, slider_step

SCALE_RANGE = (0.0, 4.0)
"""Low and high of a scale control (its default 1, stepping on the log grid)."""
SPAN = 4.0
"""A gain's control runs up to SPAN × its default."""
ZERO_STEP = 0.01
"""The step up from 0 of a scale (a gain's step from 0 is a hundredth of its range)."""


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
    rule: Rule = Rule("linear", step=ZERO_STEP)
    """How the value steps (:mod:`.steps`)."""


def rule_of(value: float, spec: GainSpec, scalars: Mapping[str, float] | None = None) -> Rule:
    """How a control of a gain declared ``spec`` whose default is ``value`` steps: whole
    multiples of the gain it names (``multiple_of``, when that gain is one of ``scalars``:
    a one-value control), linear for a fraction or a signed gain, else the log grid."""
    if spec.multiple_of and spec.multiple_of in (scalars or {}):
        return Rule("multiple", anchor=value, of=spec.multiple_of)
    if spec.bound == "fraction":
        return Rule("linear", step=FRACTION_STEP)
    if spec.bound == "any" or not math.isfinite(value):
        return Rule("linear", step=abs(value) / SIGNED_SHARE if value else ZERO_STEP)
    return Rule("log", anchor=value, step=ZERO_STEP)


def _range(value: float, spec: GainSpec) -> tuple[float, float]:
    if spec.bound == "fraction":  # 0 < value <= 1: the whole range
        return 0.0, 1.0
    top = SPAN * abs(value) if value else 1.0
    low = -top if spec.bound == "any" else 0.0
    return low, top


def _knob(
    name: str, component: int | None, label: str, value: float, spec: GainSpec, scalars: Mapping[str, float]
) -> Knob:
    low, high = _range(value, spec)
    rule = rule_of(value, spec, scalars)
    if (
        rule.kind == "log"
    ):  # up from 0 (the grid has none): to the grid value nearest a hundredth of the range
        rule = rule._replace(step=grid_nearest((high - low) / 100.0))
    if rule.kind == "multiple":  # from one of the other gain's value (mpc's horizon: one knot)
        low = min(scalars[rule.of], value)
    step = slider_step(rule, value, scalars.get(rule.of))
    return Knob(name, component, False, label, low, high, step, value, spec.doc, rule)


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
    shown_values = {n: v for n, v in values.items() if v is not None and not isinstance(v, (bool, str))}
    scalars = {  # the one-value gains: what a gain declared a multiple of another steps by
        n: float(v) for n, v in shown_values.items() if _components(v, spec_of(gains_type, n).matrix) is None
    }
    for name, value in shown_values.items():
        spec = spec_of(gains_type, name)
        unit = f" [{spec.unit}]" if spec.unit else ""
        parts = _components(value, spec.matrix)
        if parts is None:
            knobs.append(_knob(name, None, f"{name}{unit}", float(value), spec, scalars))
            continue
        what = {"joint": "joint", "axis": "axis", "estimate": "estimate"}.get(spec.per, "entry")
        for i, x in enumerate(parts):
            label = f"{name} {what} {'xyz'[i] if spec.per == 'axis' and i < 3 else i + 1}{unit}"
            knobs.append(_knob(name, i, label, x, spec, scalars))
        low, high = SCALE_RANGE
        scale = Rule("log", anchor=1.0, step=grid_nearest((high - low) / 100.0))
        step = slider_step(scale, 1.0)
        knobs.append(
            Knob(name, None, True, f"{name} × (all)", low, high, step, 1.0, f"scales every {name}", scale)
        )
    return knobs


def choices_of(gains_type: Any, values: Mapping[str, Any]) -> dict[str, tuple[tuple[str, ...], str]]:
    """Each gain in ``values`` declared as one word of a few (its spec's ``choices``): its
    words and the word it has."""
    out: dict[str, tuple[tuple[str, ...], str]] = {}
    for name, value in values.items():
        options = tuple(getattr(spec_of(gains_type, name), "choices", ()) or ())
        if options and isinstance(value, str):
            out[name] = (options, value)
    return out


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


def format_typed(value: Any) -> str:
    """A gain's value as its box shows it: ``350``, ``350, 300``, a ``(k, k)`` matrix as its
    rows ``150, 20, 0; 20, 150, 0; 0, 0, 80``; each number to the digits that matter
    (:func:`~.steps.shown`: ``159.99999999999997`` as ``160``; the value runs exactly)."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return shown(float(array))
    if array.ndim == 2:
        return "; ".join(", ".join(shown(x) for x in row) for row in array)
    return ", ".join(shown(x) for x in array.reshape(-1))


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
    "choices_of",
    "format_typed",
    "gains_from",
    "knob_changes",
    "knobs_of",
    "matrices_of",
    "parse_typed",
    "rule_of",
]
