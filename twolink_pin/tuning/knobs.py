"""The controls of a law's gains, read from its :class:`~twolink_pin.controllers.Gains`
declaration: what each control sets, its label, range and step (no widget here).

* a scalar gain: one control;
* a per-joint (per-axis, per-estimate) gain: one control per component and one that scales
  them all (the gain is component × scale);
* a matrix gain: its diagonal, one control per entry, and an overall scale (off-diagonal
  terms of a full default matrix are dropped; the page says so); a matrix given as a
  number ``s`` (``s I``): one control.

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


def gains_from(knobs: list[Knob], settings: Mapping[int, float]) -> dict[str, Any]:
    """The gains the controls ask for: knob position in ``knobs`` → value. A per-component
    gain is its components × its scale (a tuple; a matrix gain: its diagonal)."""
    parts: dict[str, list[float]] = {}
    scales: dict[str, float] = {}
    gains: dict[str, Any] = {}
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
        gains[name] = tuple(x * scale for x in values)
    return gains


__all__ = ["SCALE_RANGE", "SPAN", "Knob", "gains_from", "knobs_of", "nice_step"]
