"""The checks of one URDF ``<link>`` and one ``<joint>``, and how URDF numbers are read.

Split from :mod:`.urdf_validation`, which checks the document, the names and the tree and
calls :func:`check_link` and :func:`check_joint` for each element; its docstring lists
every check (items 4 and 5 are here). Each check raises
:class:`~twolink_pin.errors.InvalidURDFError` naming the file, the element and what was
expected.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from typing import Final, NamedTuple

import numpy as np

from twolink_pin.errors import InvalidURDFError
from twolink_pin.model.inertia_repair import InertiaRepair, inertia_matrix, nearest_consistent

JOINT_TYPES: Final[frozenset[str]] = frozenset(
    {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}
)
"""The joint types of the URDF specification."""

AXIS_JOINT_TYPES: Final[frozenset[str]] = frozenset({"revolute", "continuous", "prismatic", "planar"})
"""Joint types whose ``<axis>`` is used (the planar joint's axis is the plane's normal)."""

_LIMIT_JOINT_TYPES: Final[frozenset[str]] = frozenset({"revolute", "continuous", "prismatic"})
_BOUNDED_JOINT_TYPES: Final[frozenset[str]] = frozenset({"revolute", "prismatic"})

MAX_MASS: Final[float] = 1e6
"""Heaviest link accepted [kg]: a thousand tonnes is a unit mix-up, and far heavier masses
overflow the joint-space inertia (1e308 kg gives inf)."""
MAX_INERTIA: Final[float] = 1e8
"""Largest principal moment of inertia accepted [kg·m²] (for the same reasons)."""
TRIANGLE_RTOL: Final[float] = 1e-12
"""Relative tolerance of the triangle inequality on principal moments.

The largest principal moment may exceed the sum of the other two by this fraction of that
sum, so that a thin rod or a flat plate (equality) passes despite rounding.
"""

_INERTIA_ATTRIBUTES: Final[tuple[str, ...]] = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_DECIMAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


# --- links ----------------------------------------------------------------------------------


class LinkFindings(NamedTuple):
    """What :func:`check_link` accepted with a note, and the repair it made (if asked to)."""

    notes: tuple[str, ...] = ()
    """One line each: what was accepted that a reader may want to know."""
    repair: InertiaRepair | None = None
    """The link's inertia replaced by the nearest consistent one (``repair=True``)."""


REPAIR_HINT = (
    "(--repair-inertias, or load_robot(..., repair_inertias=True), replaces it with the nearest inertia "
    "that satisfies it and lists the change)"
)
"""What a triangle-inequality refusal offers."""
ZERO_MOMENT = 1e-12
"""A principal moment within this fraction of the largest (in magnitude) counts as 0: a thin rod's."""


def check_link(
    link: ET.Element, where: str, path: str, *, static: bool = False, repair: bool = False
) -> LinkFindings:
    """Check one ``<link>``. ``static``: the link never moves (the root link, or one fixed to it
    through fixed joints only): its mass and inertia are then read but not required to be a
    body's (a mass 0 with an inertia, as a static base is often written, is accepted with a
    note). ``repair``: an inertia that breaks the triangle inequality is replaced in ``link``
    by the nearest one that satisfies it (:mod:`~twolink_pin.model.inertia_repair`) instead of refused."""
    inertials = link.findall("inertial")
    if not inertials:
        return LinkFindings()  # A massless link (e.g. a base or an end-effector frame) is fine.
    if len(inertials) > 1:
        raise InvalidURDFError(
            path, f"{where} <inertial>", f"appears {len(inertials)} times; expected at most one per link"
        )
    inertial = inertials[0]
    name, where = where, f"{where} <inertial>"
    mass = inertial.find("mass")
    if mass is None:
        raise InvalidURDFError(
            path, f"{where}<mass>", 'missing; expected <mass value="..."/> with a finite number > 0 kg'
        )
    raw = mass.get("value")
    if raw is None:
        raise InvalidURDFError(path, f"{where}<mass>", "value is missing; expected a finite number > 0 kg")
    value = _finite_float(raw)
    inertia = inertial.find("inertia")
    _check_origin(inertial.find("origin"), f"{where}<origin>", path)
    if static and value is not None and value >= 0.0:
        if inertia is not None:
            _inertia_values(inertia, f"{where}<inertia>", path)  # numbers Pinocchio reads, whatever they mean
        try:
            _check_body(value, raw, inertia, where, path, repair=False)
        except InvalidURDFError as err:
            return LinkFindings(
                (f"{name} never moves (fixed to the root link): accepted although {err.reason}",)
            )
        return LinkFindings()
    return _check_body(value, raw, inertia, where, path, repair=repair)


def _check_body(
    value: float | None, raw: str, inertia: ET.Element | None, where: str, path: str, *, repair: bool
) -> LinkFindings:
    """The mass ``value`` (as ``raw``) and ``<inertia>`` of a link that moves."""
    if value == 0.0 and _is_zero_inertia(inertia):
        return LinkFindings()  # An explicitly massless link (mass 0, inertia 0), common for frame links.
    if value is None or not value > 0.0:
        raise InvalidURDFError(path, f"{where}<mass>", f'mass value="{raw}" must be a finite number > 0 kg')
    if value > MAX_MASS:
        raise InvalidURDFError(
            path,
            f"{where}<mass>",
            f'mass value="{raw}" is more than {MAX_MASS:g} kg; expected an arm\'s link',
        )
    if inertia is not None and _is_zero_inertia(inertia):  # all zeros: a point mass, fine
        return LinkFindings()
    return _check_inertia(inertia, f"{where}<inertia>", path, repair=repair)


def _is_zero_inertia(inertia: ET.Element | None) -> bool:
    """Whether ``<inertia>`` is absent or has all six entries exactly 0."""
    if inertia is None:
        return True
    return all(_finite_float(inertia.get(name, "0")) == 0.0 for name in _INERTIA_ATTRIBUTES)


def _inertia_values(inertia: ET.Element | None, where: str, path: str) -> tuple[float, ...]:
    """The six finite ``ixx … izz`` of ``<inertia>`` [kg·m²]."""
    if inertia is None:
        raise InvalidURDFError(
            path,
            where,
            "missing; expected <inertia ixx ixy ixz iyy iyz izz/> in kg m^2 about the centre of mass",
        )
    missing = [name for name in _INERTIA_ATTRIBUTES if inertia.get(name) is None]
    if missing:
        raise InvalidURDFError(
            path,
            where,
            f"missing attribute(s) {', '.join(missing)}; "
            f"expected all six of {', '.join(_INERTIA_ATTRIBUTES)}",
        )
    values = []
    for name in _INERTIA_ATTRIBUTES:
        raw = inertia.get(name, "")
        value = _finite_float(raw)
        if value is None:
            raise InvalidURDFError(path, where, f'{name}="{raw}" must be a finite number (kg m^2)')
        values.append(value)
    return tuple(values)


def _check_inertia(
    inertia: ET.Element | None, where: str, path: str, *, repair: bool = False
) -> LinkFindings:
    values = _inertia_values(inertia, where, path)
    assert inertia is not None
    with np.errstate(all="ignore"):
        moments = np.linalg.eigvalsh(inertia_matrix(values))  # ascending
    shown = ", ".join(f"{m:.6g}" for m in moments)
    if not np.all(np.isfinite(moments)):
        raise InvalidURDFError(
            path, where, f"principal moments ({shown}) are not finite; expected moderate values in kg m^2"
        )
    small, middle, large = (float(m) for m in moments)
    notes: tuple[str, ...] = ()
    if not small > 0.0:
        if small < -ZERO_MOMENT * max(abs(large), 1e-300) or not large > 0.0:
            raise InvalidURDFError(
                path,
                where,
                f"inertia matrix is not positive semidefinite: its eigenvalues are ({shown}) kg m^2; "
                "expected all >= 0 (0 only for a thin rod's axis)",
            )
        notes = (
            f"{where}: a principal moment is 0 ({shown} kg·m²: a thin rod); accepted, as the arm's M(q) "
            "is positive definite",
        )
    if large > MAX_INERTIA:
        raise InvalidURDFError(
            path,
            where,
            f"principal moment {large:.6g} kg m^2 is more than {MAX_INERTIA:g}; expected an arm's link",
        )
    if large > (small + middle) * (1.0 + TRIANGLE_RTOL):
        if not repair:
            raise InvalidURDFError(
                path,
                where,
                f"principal moments ({shown}) kg m^2 violate the triangle inequality: {large:.6g} > "
                f"{small:.6g} + {middle:.6g}; expected each moment <= the sum of the other two {REPAIR_HINT}",
            )
        fixed = nearest_consistent(where.split("'")[1] if "'" in where else where, values)
        for name, number in zip(_INERTIA_ATTRIBUTES, fixed.after, strict=True):
            inertia.set(name, repr(number))
        return LinkFindings(notes, fixed)
    return LinkFindings(notes)


def _check_origin(origin: ET.Element | None, where: str, path: str) -> None:
    if origin is None:
        return
    for attribute, unit in (("xyz", "m"), ("rpy", "rad")):
        raw = origin.get(attribute)
        if raw is not None and _finite_vector(raw) is None:
            raise InvalidURDFError(path, where, f'{attribute}="{raw}" must be 3 finite numbers ({unit})')


# --- joints ---------------------------------------------------------------------------------


def check_joint(
    joint: ET.Element, where: str, link_names: Sequence[str], known: set[str], path: str
) -> tuple[str, str]:
    """Check one joint and return its (parent, child) link names."""
    joint_type = joint.get("type")
    expected_types = ", ".join(sorted(JOINT_TYPES))
    if joint_type is None:
        raise InvalidURDFError(path, where, f"has no type; expected one of {expected_types}")
    if joint_type not in JOINT_TYPES:
        raise InvalidURDFError(
            path, where, f'type="{joint_type}" is not a URDF joint type; expected one of {expected_types}'
        )

    parent = _link_reference(joint, "parent", known, link_names, where, path)
    child = _link_reference(joint, "child", known, link_names, where, path)
    if parent == child:
        raise InvalidURDFError(
            path, f"{where} <child>", f"link '{child}' is also the parent; expected two different links"
        )

    _check_origin(joint.find("origin"), f"{where} <origin>", path)

    axis = joint.find("axis")
    if joint_type in AXIS_JOINT_TYPES and axis is not None:
        raw = axis.get("xyz")
        if raw is not None:  # No xyz: URDF's default axis 1 0 0.
            vector = _finite_vector(raw)
            if vector is None or not math.hypot(*vector) > 0.0:
                raise InvalidURDFError(
                    path,
                    f"{where} <axis>",
                    f'xyz="{raw}" must be 3 finite numbers with a nonzero norm (URDF default: 1 0 0)',
                )

    limit = joint.find("limit")
    if joint_type in _LIMIT_JOINT_TYPES and limit is not None:
        _check_limit(limit, joint_type, f"{where} <limit>", path)
    return parent, child


def _link_reference(
    joint: ET.Element, tag: str, known: set[str], link_names: Sequence[str], where: str, path: str
) -> str:
    element = joint.find(tag)
    name = None if element is None else element.get("link")
    if name is None:
        raise InvalidURDFError(
            path, f"{where} <{tag}>", f'missing; expected <{tag} link="..."/> naming a declared link'
        )
    if name not in known:
        raise InvalidURDFError(
            path,
            f"{where} <{tag}>",
            f'link="{name}" names no declared link; expected one of {quoted_names(link_names)}',
        )
    return name


def _check_limit(limit: ET.Element, joint_type: str, where: str, path: str) -> None:
    prismatic = joint_type == "prismatic"
    units = {
        "effort": "N" if prismatic else "N m",
        "velocity": "m/s" if prismatic else "rad/s",
        "lower": "m" if prismatic else "rad",
        "upper": "m" if prismatic else "rad",
    }
    for attribute in ("effort", "velocity"):
        raw = limit.get(attribute)
        if raw is None:
            raise InvalidURDFError(
                path,
                where,
                f"{attribute} is missing; URDF requires <limit effort=... velocity=...> ({units[attribute]}; 0 for none)",
            )
        value = _finite_float(raw)
        if value is None or not value >= 0.0:
            raise InvalidURDFError(
                path, where, f'{attribute}="{raw}" must be a finite number >= 0 ({units[attribute]})'
            )
    if joint_type not in _BOUNDED_JOINT_TYPES:
        return
    bounds = []
    for attribute in ("lower", "upper"):
        raw = limit.get(attribute, "0")  # URDF default: 0.
        value = _finite_float(raw)
        if value is None:
            raise InvalidURDFError(
                path, where, f'{attribute}="{raw}" must be a finite number ({units[attribute]})'
            )
        bounds.append(value)
    lower, upper = bounds
    if lower > upper:
        raise InvalidURDFError(
            path,
            where,
            f'lower="{limit.get("lower", "0")}" > upper="{limit.get("upper", "0")}"; expected lower <= upper '
            f"({units['lower']}; an absent bound defaults to 0)",
        )


# --- numbers --------------------------------------------------------------------------------


def _finite_float(raw: str) -> float | None:
    """The value of a decimal literal, or None if ``raw`` is not one or is not finite."""
    text = raw.strip()
    if not _DECIMAL.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def _finite_vector(raw: str) -> tuple[float, float, float] | None:
    """Three whitespace-separated finite numbers, or None."""
    parts = raw.split()
    if len(parts) != 3:
        return None
    values = [_finite_float(part) for part in parts]
    if any(value is None for value in values):
        return None
    x, y, z = (float(value) for value in values if value is not None)
    return x, y, z


def quoted_names(names: Iterable[str], count: int = 5) -> str:
    """Up to ``count`` quoted names, for a message."""
    names = list(names)
    shown = ", ".join(f"'{name}'" for name in names[:count])
    return shown + (f", ... ({len(names)} in all)" if len(names) > count else "")
