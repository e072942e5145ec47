"""Identified parameters as a file, and the laws they seed: identify, then control with it.

``twolink-pin identify --save FILE.json`` writes the JSON document ``--json`` prints: the robot,
then ``"parameters"``, one object per parameter with ``name``, ``unit``, ``kind``,
``estimate``, ``std``, ``relative_std_percent`` and ``true`` (null for measured data), and
the fit's diagnostics. :func:`read_parameter_file` reads it back for a robot: every base
parameter of the robot must be there under the name ``twolink-pin info --json`` lists;
``V1..Vn`` and ``C1..Cn`` (friction) are optional.

A law works in its robot's parameter map ``p``, which for every robot but the twolink *is*
the base parameters (same names). The twolink's laws use the report's lumped
``(p1, p2, p3)``; :func:`map_parameters` converts generically: the ``p`` whose regressor
reproduces the base parameters' torques at random states (least squares, exact when the
map can express ``β``: for the twolink ``p1 = β1 + β4``, ``p2 = β4``, ``p3 = l1 β2``). A part of
``β`` the map cannot express (the twolink's ``link2.mcy``) is dropped when it is noise (within
3σ of 0, or negligible torque), and refused, naming the parameter, when it is significant. A
file without σ (a URDF, a parameter file whose ``std`` is null) cannot tell noise from an
offset: such a part is dropped while its torques stay within :data:`UNKNOWN_SIGMA_TOLERANCE`
of the model's.

:func:`believed` gives what a law takes from them (:meth:`~twolink_pin.run_spec.RunSpec.build`
builds the law once with it): ``mode="model"`` (``--model``)
makes the identified values what the law *believes* (model-based laws' model; adaptive laws'
``p̂(0) = initial_estimate × p``; a friction-estimating law's friction), ``mode="p0"``
(``--p0``, laws that estimate) starts the estimates *at* them (initial-estimate factors 1).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

from twolink_pin.documents import load_json
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InputFileError, InvalidParameterError
from twolink_pin.files import read_input_file
from twolink_pin.identification.observation import ParameterSet
from twolink_pin.model import RobotModel

FORMAT = "twolink-pin identified parameters"
"""The ``format`` field of a parameter file."""
VERSION = 1
"""Its version."""
MAX_PARAMETER_BYTES = 4 << 20
"""Largest parameter file read (4 MiB)."""
EXPRESSED_TOLERANCE = 1e-6
"""A part of β the map cannot express is ignored below this fraction of the torques it acts on."""
SIGNIFICANCE = 3.0
"""... or within this many standard deviations of zero."""
UNKNOWN_SIGMA_TOLERANCE = 0.01
"""Without a σ (a URDF), a part of β the map cannot express is dropped below this fraction of
the torques it acts on: 1 %, ten times what the noisy fits of ``identify --noise-tau 0.5``
leave there (the twolink's ``link2.mcy``: 0.025 %), and far below the model errors the laws
are shown to tolerate (the docs' demos believe links 20 % light)."""
MAX_ESTIMATE = 1e9
"""Largest magnitude of an estimate or its σ in a parameter file [kg, kg·m, kg·m²; N·m·s/rad,
N·m]: ten times the largest principal inertia a URDF may give (1e8 kg·m²,
:mod:`twolink_pin.model.urdf_elements`), far beyond any arm's; the physical-consistency check's
solver declared 1e12 'infeasible' and 1e300 'unbounded' without naming the file."""
MODES = ("model", "p0")
"""How identified parameters seed a law (module docstring)."""


class IdentifiedParameters(NamedTuple):
    """Identified values for a robot, read from a parameter file."""

    source: str
    """The file."""
    base: np.ndarray
    """Base parameters ``β̂`` in the robot's base-map order."""
    base_std: np.ndarray
    """Their standard deviations (NaN where the file gives none: a URDF, a null ``std``)."""
    friction: Friction | None
    """Identified friction (negative estimates clipped to 0), or None if the file has none."""
    notes: tuple[str, ...] = ()
    """What was adjusted (clipped friction), for the user."""


def identification_document(identification: Any, robot: RobotModel) -> dict[str, Any]:
    """The JSON document of an :class:`~twolink_pin.identification.least_squares.Identification`
    (what ``identify --json`` prints and ``--save`` writes)."""
    validation = identification.validation
    return {
        "format": FORMAT,
        "version": VERSION,
        "robot": robot.name,
        "nv": robot.nv,
        "source": identification.source,
        "parameters": identification.parameters(),
        "condition_number": identification.condition_number,
        "weighted_condition_number": identification.weighted_condition_number,
        "residual_rms": identification.residual_rms.tolist(),
        "joint_sigma": identification.joint_sigma.tolist(),
        "validation_rms": None if validation is None else validation.rms.tolist(),
        "validation_interval": None
        if validation is None
        else [float(validation.t[0]), float(validation.t[-1])],
        "fit_interval": list(identification.fit_interval),
        "samples": identification.samples,
        "fit_samples": identification.fit_samples,
        "stride": identification.stride,
        "weighted": identification.weighted,
        "method": identification.method,
        "filter": {
            "type": f"Butterworth order {identification.order}, zero phase (forward-backward)",
            "cutoff_hz": identification.cutoff_hz,
            "guard_s": identification.guard,
            "sampling_hz": 1.0 / identification.dt,
            "resampled": identification.resampled,
        },
        "velocity_check_rms": None
        if identification.velocity_check is None
        else identification.velocity_check.tolist(),
    }


def _number(path: str, where: str, value: Any, what: str) -> float:
    """``value`` as a float: a finite number of magnitude at most :data:`MAX_ESTIMATE`, else an
    error naming the file, the entry and the value."""
    if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise InputFileError(path, f"{where}: {value!r} is not {what}")
    if abs(value) > MAX_ESTIMATE:
        raise InputFileError(path, f"{where}: {value:.6g} is beyond ±{MAX_ESTIMATE:g}, no arm's value")
    return float(value)


def urdf_parameters(path: str | os.PathLike[str], robot: RobotModel) -> IdentifiedParameters:
    """The parameters a URDF's inertias give ``robot``'s base map (``--model FILE.urdf``: the law
    believes them while the plant stays ``robot``); its ``<dynamics damping friction>`` is the
    believed friction when it has any.

    Raises:
        InvalidURDFError: not a URDF twolink-pin can load.
        InputFileError: a URDF of another arm (joint count or names).
    """
    from twolink_pin.model import load_robot

    file = str(path)
    believed_robot = load_robot(path)
    names = tuple(robot.model.names)[1:]
    if believed_robot.nv != robot.nv or tuple(believed_robot.model.names)[1:] != names:
        raise InputFileError(
            file,
            f"has the joints {list(believed_robot.model.names)[1:]}; expected {robot.name}'s {list(names)} "
            "(a model of the same arm, e.g. from info or identify --write-urdf)",
        )
    base = ParameterSet.of(robot, friction=False).base.values(believed_robot.model)
    urdf = believed_robot.urdf_friction
    return IdentifiedParameters(  # a URDF carries no σ
        file,
        np.asarray(base, dtype=float),
        np.full(len(base), np.nan),
        None if urdf is None else Friction(*urdf),
    )


def read_parameter_file(path: str | os.PathLike[str], robot: RobotModel) -> IdentifiedParameters:
    """The identified parameters a file gives ``robot`` (see the module docstring).

    Raises:
        InputFileError: not a readable parameter file, another robot's (joint count or
            parameter names), a missing base parameter, a value that is not a finite number,
            base parameters no physical masses and inertias give (the link named).
    """
    file = str(path)
    raw = read_input_file(path, MAX_PARAMETER_BYTES, "an identified-parameter file (.json)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputFileError(file, f"is not valid JSON: {err}") from None
    document = load_json(text, file)  # nesting bounded, repeated keys refused
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise InputFileError(
            file,
            f'is not a parameter file: expected a JSON object with "format": "{FORMAT}" '
            "(twolink-pin identify --save FILE.json writes one)",
        )
    if document.get("nv") != robot.nv:
        raise InputFileError(
            file,
            f"says nv = {document.get('nv')!r} (robot {document.get('robot')!r}); expected nv = {robot.nv}, the "
            f"joint count of {robot.name}",
        )
    rows = document.get("parameters")
    if not isinstance(rows, list):
        raise InputFileError(file, 'has no "parameters" list')
    values: dict[str, tuple[float, float]] = {}
    for k, row in enumerate(rows):
        if not isinstance(row, dict) or not isinstance(row.get("name"), str):
            raise InputFileError(file, f'parameters[{k}]: expected an object with a "name"')
        name = row["name"]
        if name in values:
            raise InputFileError(
                file, f"parameters[{k}] repeats the name {name!r}; expected each parameter once"
            )
        bounded = f"a finite number within ±{MAX_ESTIMATE:g}"
        estimate = _number(file, f"parameters[{k}] ({name}).estimate", row.get("estimate"), bounded)
        std = row.get("std")
        sigma = math.nan if std is None else _number(file, f"parameters[{k}] ({name}).std", std, bounded)
        values[name] = (estimate, abs(sigma))
    pset = ParameterSet.of(robot, friction=True)
    base_names = pset.base.names
    missing = [n for n in base_names if n not in values]
    if missing:
        raise InputFileError(
            file,
            f"lacks {robot.name}'s base parameter{'s' if len(missing) > 1 else ''} {', '.join(repr(m) for m in missing[:3])}"
            f"{' …' if len(missing) > 3 else ''} (its parameters are those of twolink-pin info --robot {robot.name} --json; "
            f"the file has {', '.join(repr(n) for n in list(values)[:4])}{' …' if len(values) > 4 else ''})",
        )
    base = np.array([values[n][0] for n in base_names])
    base_std = np.array([values[n][1] for n in base_names])
    _refuse_unphysical(file, robot, pset, base)
    friction_names = pset.names[pset.base.size :]
    friction = None
    notes: list[str] = []
    present = [n for n in friction_names if n in values]
    if present and len(present) != len(friction_names):
        absent = [n for n in friction_names if n not in values]
        raise InputFileError(file, f"gives some friction coefficients but not {', '.join(absent)}")
    if present:
        coefficients = np.array([values[n][0] for n in friction_names])
        negative = [n for n, x in zip(friction_names, coefficients) if x < 0]
        if negative:
            notes.append(f"negative friction estimates {', '.join(negative)} clipped to 0")
        coefficients = np.maximum(coefficients, 0.0)
        friction = Friction(tuple(coefficients[: robot.nv]), tuple(coefficients[robot.nv :]))
    return IdentifiedParameters(file, base, base_std, friction, tuple(notes))


def _refuse_unphysical(file: str, robot: RobotModel, pset: ParameterSet, base: np.ndarray) -> None:
    """Refuse base parameters that no physical masses and inertias give (the file holds base
    parameters, so this asks whether *some* standard parameters with every link's
    pseudo-inertia ⪰ 0 reproduce them: :func:`~twolink_pin.identification.physical.consistency`)."""
    from twolink_pin.identification.physical import consistency

    try:
        check = consistency(robot, pset.base, base)
    except InvalidParameterError as exc:  # the solver gave up: say which file it was checking
        raise InputFileError(
            file, f"its base parameters could not be checked for physical consistency ({exc})"
        ) from None
    if not check.feasible:
        link, least = next(
            (n, s) for n, s in zip(check.links, check.least_eigenvalue) if s < -check.tolerance
        )
        others = [n for n in check.infeasible if n != link]
        raise InputFileError(
            file,
            f"link '{link}': physically impossible base parameters: no mass, centre of mass and inertia make its "
            f"pseudo-inertia positive semidefinite (its least eigenvalue is {least:.3g} kg·m² at best; Wensing, Kim & "
            f"Slotine 2017)"
            + (f"; also {', '.join(others)}" if others else "")
            + ": identify --physical gives parameters that are",
        )


def _stacked(robot: RobotModel, matrix: np.ndarray, samples: int = 40, seed: int = 7) -> np.ndarray:
    """``Y_π matrix`` stacked at seeded random states within the joint limits."""
    import pinocchio as pin

    model = robot.model
    data = model.createData()
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(samples):
        q = rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi))
        v, a = rng.uniform(-2.0, 2.0, (2, model.nv))
        rows.append(pin.computeJointTorqueRegressor(model, data, q, v, a) @ matrix)
    return np.vstack(rows)


def map_parameters(robot: RobotModel, identified: IdentifiedParameters) -> np.ndarray:
    """The robot's map parameters ``p`` that the identified base parameters give (module
    docstring).

    Raises:
        InvalidParameterError: ``β̂`` has a part the map cannot express that is significant
            (beyond :data:`SIGNIFICANCE` σ and :data:`EXPRESSED_TOLERANCE` of the torques).
    """
    pset = ParameterSet.of(robot)
    if robot.parameter_map.names == pset.base.names:
        return np.array(identified.base, dtype=float)
    A_beta = _stacked(robot, pset.base.matrix)
    A_p = _stacked(robot, robot.parameter_map.matrix)
    L = np.linalg.lstsq(A_p, A_beta, rcond=None)[0]  # p = L β
    unexplained = A_beta - A_p @ L  # what of each β column the map cannot produce
    _, s, Vt = np.linalg.svd(unexplained, full_matrices=False)
    directions = Vt[s > 1e-9 * max(float(np.linalg.svd(A_beta, compute_uv=False)[0]), 1e-300)]
    torques = A_beta @ identified.base
    scale = float(np.linalg.norm(torques)) or 1.0
    for d in directions:
        value = float(d @ identified.base)
        effect = float(np.linalg.norm(unexplained @ (d * value))) / scale
        _refuse_if_significant(robot, identified, pset, d, value, effect)
    expressible = identified.base - directions.T @ (directions @ identified.base)  # the rest is noise
    return L @ expressible


def _refuse_if_significant(
    robot: RobotModel,
    identified: IdentifiedParameters,
    pset: ParameterSet,
    d: np.ndarray,
    value: float,
    effect: float,
) -> None:
    """Refuse the part ``value`` of ``β̂`` along ``d`` (which the map cannot express, its torques
    ``effect`` of the model's) when it is significant: beyond :data:`SIGNIFICANCE` σ and
    :data:`EXPRESSED_TOLERANCE` of the torques; without σ, beyond :data:`UNKNOWN_SIGMA_TOLERANCE`."""
    support = np.abs(d) > 1e-12
    known = bool(np.isfinite(identified.base_std[support]).all())
    main = int(np.argmax(np.abs(d)))
    name, unit = pset.base.names[main], pset.base.units[main]
    expected = f"a value {robot.name}'s parameter map ({', '.join(robot.parameter_map.names)}) can express: it has no such parameter"
    if known:
        sigma = float(np.sqrt(np.sum((d[support] * identified.base_std[support]) ** 2)))
        if effect > EXPRESSED_TOLERANCE and abs(value) > SIGNIFICANCE * sigma:
            raise InvalidParameterError(
                f"{identified.source}: {name}",
                f"{identified.base[main]:.6g} ± {identified.base_std[main]:.2g} {unit}",
                f"{expected}, and this one {_sigmas(abs(value), sigma)} "
                f"(its torques are {100 * effect:.2g} % of the model's)",
            )
    elif effect > UNKNOWN_SIGMA_TOLERANCE:
        raise InvalidParameterError(
            f"{identified.source}: {name}",
            f"{identified.base[main]:.6g} {unit}",
            f"{expected}, and its torques are {100 * effect:.2g} % of the model's (the file gives no σ to tell "
            f"noise from an offset: at most {100 * UNKNOWN_SIGMA_TOLERANCE:g} % is left out)",
        )


def _sigmas(value: float, sigma: float) -> str:
    """How far ``value`` is from 0 in standard deviations ``sigma``, for a message."""
    if sigma <= 0:
        return "is given with σ = 0, so it is no noise"
    ratio = value / sigma
    return f"is {ratio:.1f} σ from 0" if ratio < 1e6 else f"is {ratio:.3g} σ from 0"


class Belief(NamedTuple):
    """What a law takes from identified parameters (:func:`believed`)."""

    parameters: np.ndarray
    """The parameters of the robot's map the law's model believes."""
    friction: Friction | None
    """The friction a friction-estimating law believes (None: its robot's)."""
    gains: dict[str, Any]
    """The law's gains, with ``initial_estimate`` 1 for ``p0`` (the estimates start there)."""


def believed(
    law: Any, robot: RobotModel, identified: IdentifiedParameters, mode: str, gains: Mapping[str, Any]
) -> Belief:
    """What the law ``law`` believes of ``identified`` (``mode="model"``: its model;
    ``mode="p0"``: its estimates' start); :meth:`~twolink_pin.run_spec.RunSpec.build` builds
    the law with it once, on the true robot's plant.

    Raises:
        InvalidParameterError: an unknown mode, ``p0`` for a law that estimates nothing, or
            parameters the robot's map cannot express (:func:`map_parameters`).
    """
    from twolink_pin.scenario import law_class

    if mode not in MODES:
        raise InvalidParameterError("mode", mode, f"one of {', '.join(MODES)}")
    cls = law_class(law)
    if mode == "p0" and not cls.estimates:
        raise InvalidParameterError(
            "--p0",
            identified.source,
            f"a law that estimates parameters ('{cls.name}' estimates none: give its model with --model FILE)",
        )
    p = map_parameters(robot, identified)
    changes = dict(gains)
    if mode == "p0":
        for name in ("initial_estimate", "friction_initial_estimate"):
            if cls.takes(name):
                changes.setdefault(name, 1.0)
    friction = identified.friction if "friction" in cls.estimates else None
    return Belief(p, friction, changes)
