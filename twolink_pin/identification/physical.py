"""Physically consistent identification: every link's pseudo-inertia positive semidefinite.

Least squares gives base parameters ``β̂`` that reproduce the torques, but nothing keeps them
physical: a poorly excited log can give a link a negative inertia. A rigid body's ten
standard parameters ``π_i = (m, m c, I)`` (``I`` about the joint frame's origin, Pinocchio's
order) are **physically consistent** — a non-negative mass density exists that has them — if
and only if its **pseudo-inertia** (Wensing, Kim & Slotine 2017, "Linear matrix inequalities
for physically consistent inertial parameter identification", IEEE RA-L 3(1))::

    J_i = [[Σ_i, h_i], [h_iᵀ, m_i]] ⪰ 0,    Σ_i = ½ tr(I_i) 𝟙 − I_i,   h_i = m_i c_i

is positive semidefinite (it implies ``m ≥ 0``, the inertia's triangle inequalities, and the
centre of mass inside the body's inertia ellipsoid). ``β = B π`` is linear, so:

* :func:`consistency`: how far base parameters ``β`` are from any physical ``π``: the SDP
  ``max Σ_i s_i`` over ``π`` with ``B π = β``, ``J_i(π) ⪰ s_i 𝟙``, ``s_i ≤ 0``. A link with
  ``s_i < 0`` at the optimum cannot be made physical, whatever the parameters ``β`` does
  not fix (``s_i`` is the least negative eigenvalue its pseudo-inertia can have [SI: kg·m²,
  the pseudo-inertia's ``Σ`` block]; the sum spreads no violation onto a link that can avoid it).
* :func:`physical_fit`: the weighted least squares of :func:`~twolink_pin.identification.least_squares.identify`
  on the standard parameters, subject to every ``J_i ⪰ 0`` and friction ``≥ 0``. With ``G``
  the weighted Gram matrix of the fitted rows and ``θ̂`` the unconstrained weighted estimate,
  ``‖y_w − W_w θ‖² = (θ − θ̂)ᵀ G (θ − θ̂) + const`` exactly, so the constrained fit is
  ``min (θ − θ̂)ᵀ G (θ − θ̂)`` over ``θ = (B π, f)``, a small SDP (the rows are not needed
  again). With instrumental variables ``θ̂`` is the IV estimate and this the projection of it,
  in the same metric, onto the physical set.

Solved with `cvxpy <https://www.cvxpy.org>`_ and the interior-point solver Clarabel. The
standard deviations reported for the constrained estimate are the unconstrained ones: an
active constraint adds information the linearised covariance does not hold (and biases the
estimate towards the boundary), which they do not contain.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.model.base_parameters import BaseParameterMap, body_name
from twolink_pin.model.catalog import catalog_profile_name
from twolink_pin.model.parameters import N_BODY_PARAMETERS
from twolink_pin.model.urdf_profile import declare_profile

MARGIN = 1e-6
"""The constrained fit asks ``J_i ⪰ MARGIN 𝟙`` [kg·m²], not just ``⪰ 0``: a body strictly inside
the physical set, whose inertia about its centre of mass is positive definite and within the
triangle inequality by ``2 MARGIN`` (what a URDF and its validator need; on the boundary the
solver's 1e-8 would leave it to rounding)."""
PRIOR_LENGTH = 0.1
"""Length scale [m] of the distance to the model's own parameters in :func:`nearest_physical`:
a body's mass counts in units of its URDF mass ``m``, first moments of ``m × 0.1 m``, inertias
of ``m × (0.1 m)²``."""
REGULARISATION = 1e-9
"""Weight of the model's own standard parameters (a prior, scaled by :data:`PRIOR_LENGTH`) in
the constrained fit, relative to the mean diagonal of the Gram matrix. It decides what no
torque depends on (left free, the solver put 2.5e5 kg on a yaw joint's link) and, weakly,
what the log hardly excites: on the 3-link test's poorly excited log it moved
``link2.Iyy + 0.16 link3.m`` from 0.100 to 0.110 (σ 8.45); on a well-excited log it is
below the noise."""
TIE = 0.01
"""Validation RMS values within this fraction of each other are a tie."""
TOLERANCE = 1e-7
"""A link whose least eigenvalue is below ``−TOLERANCE × scale`` is infeasible (scale: the
largest |β|, at least 1): the solver's accuracy is about 1e-8."""


def pseudo_inertia(pi: np.ndarray) -> np.ndarray:
    """The 4×4 pseudo-inertia of one body's ten parameters (Pinocchio's order)."""
    m, mcx, mcy, mcz, ixx, ixy, iyy, ixz, iyz, izz = (float(x) for x in pi)
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    sigma = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    return np.block(
        [[sigma, np.array([[mcx], [mcy], [mcz]])], [np.array([[mcx, mcy, mcz]]), np.array([[m]])]]
    )


def link_names(robot: RobotModel) -> tuple[str, ...]:
    """The name of each moving body (the link its joint moves)."""
    return tuple(body_name(robot.model, j) for j in range(1, robot.model.njoints))


def _parameters_of(J: object) -> list[object]:
    """The ten parameters (Pinocchio's order) as expressions of a pseudo-inertia variable."""
    import cvxpy as cp

    assert isinstance(J, cp.Variable)
    sxx, syy, szz = J[0, 0], J[1, 1], J[2, 2]
    return [
        J[3, 3],
        J[0, 3],
        J[1, 3],
        J[2, 3],
        syy + szz,
        -J[0, 1],
        sxx + szz,
        -J[0, 2],
        -J[1, 2],
        sxx + syy,
    ]


def _solve(problem: object) -> None:
    import cvxpy as cp

    assert isinstance(problem, cp.Problem)
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.SolverError as exc:
        raise InvalidParameterError("physical fit", str(exc), "a problem Clarabel solves") from None
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        raise InvalidParameterError("physical fit", problem.status, "an optimal solution from Clarabel")


@dataclass(frozen=True)
class Consistency:
    """How far base parameters are from physical ones (:func:`consistency`)."""

    links: tuple[str, ...]
    """Link names."""
    least_eigenvalue: np.ndarray
    """Per link, the least negative λ_min(J_i) any standard parameters with these β allow (0 if
    the link can be physical) [kg·m²]."""
    standard: np.ndarray
    """Standard parameters π at that optimum, shape (10 n_b,)."""
    tolerance: float
    """Below ``−tolerance`` a link counts as infeasible."""

    @property
    def infeasible(self) -> tuple[str, ...]:
        """Links that cannot be physical."""
        return tuple(n for n, s in zip(self.links, self.least_eigenvalue) if s < -self.tolerance)

    @property
    def feasible(self) -> bool:
        return not self.infeasible

    def describe(self) -> str:
        """One line: which links are infeasible and by how much, or that all are feasible."""
        if self.feasible:
            return "every link's pseudo-inertia can be positive semidefinite (physically consistent)"
        return "infeasible: " + ", ".join(
            f"{n} (pseudo-inertia λ_min ≥ {s:.3g} kg·m² at best)"
            for n, s in zip(self.links, self.least_eigenvalue)
            if s < -self.tolerance
        )


def consistency(
    robot: RobotModel, base_map: BaseParameterMap, beta: np.ndarray, margin: float = 0.0
) -> Consistency:
    """Whether some physical standard parameters give the base parameters ``beta`` (module
    docstring); per link the least violation of ``J_i ⪰ 0`` they must have. With ``margin`` > 0
    the links are pushed up to ``J_i ⪰ margin 𝟙`` where ``beta`` allows (``s_i <= margin``)."""
    import cvxpy as cp

    bodies = robot.model.njoints - 1
    Js = [cp.Variable((4, 4), symmetric=True) for _ in range(bodies)]
    s = cp.Variable(bodies)
    pi = cp.hstack([p for J in Js for p in _parameters_of(J)])
    constraints = [base_map.combination @ pi == np.asarray(beta, dtype=float), s <= margin]
    constraints += [Js[i] - s[i] * np.eye(4) >> 0 for i in range(bodies)]
    _solve(cp.Problem(cp.Maximize(cp.sum(s)), constraints))
    scale = max(1.0, float(np.max(np.abs(beta)))) if np.size(beta) else 1.0
    value = np.asarray(pi.value, dtype=float)
    least = np.array(
        [
            min(0.0, float(np.linalg.eigvalsh(pseudo_inertia(value[10 * i : 10 * i + 10]))[0]))
            for i in range(bodies)
        ]
    )
    return Consistency(link_names(robot), least, value, TOLERANCE * scale)


@dataclass(frozen=True)
class PhysicalFit:
    """The constrained estimate."""

    theta: np.ndarray
    """``(β, V, C)`` constrained, shape (n_θ,)."""
    standard: np.ndarray
    """Standard parameters π of the fit, shape (10 n_b,); ``β = B π`` exactly. The parts of π
    no torque depends on are the model's own (:data:`REGULARISATION`)."""
    friction: np.ndarray
    """``(V, C)`` ≥ 0, shape (2 n,) (empty without friction)."""
    least_eigenvalue: np.ndarray
    """λ_min(J_i) of each link at ``standard`` [kg·m²] (≥ 0 to solver accuracy)."""


def _prior_scale(robot: RobotModel) -> tuple[np.ndarray, np.ndarray]:
    """The model's own standard parameters and their scale (:data:`PRIOR_LENGTH`)."""
    from twolink_pin.model.parameters import inertial_parameters

    prior = inertial_parameters(robot.model)
    mass = np.maximum(prior[0::N_BODY_PARAMETERS], 1e-3)
    L = PRIOR_LENGTH
    return prior, np.concatenate([[m, m * L, m * L, m * L] + [m * L * L] * 6 for m in mass])


def physical_fit(
    robot: RobotModel,
    base_map: BaseParameterMap,
    estimate: np.ndarray,
    gram: np.ndarray,
    friction: bool = True,
    regularisation: float = REGULARISATION,
) -> PhysicalFit:
    """``min (θ − θ̂)ᵀ G (θ − θ̂)`` over physical ``θ = (B π, f)``, ``f ≥ 0`` (module docstring)."""
    import cvxpy as cp

    bodies = robot.model.njoints - 1
    nf = 2 * robot.nv if friction else 0
    G = 0.5 * (gram + gram.T)
    w, V = np.linalg.eigh(G)
    L = (V * np.sqrt(np.maximum(w, 0.0))).T  # G = Lᵀ L
    Js = [cp.Variable((4, 4), symmetric=True) for _ in range(bodies)]
    pi = cp.hstack([p for J in Js for p in _parameters_of(J)])
    f = cp.Variable(nf) if nf else None
    beta = base_map.combination @ pi
    theta = cp.hstack([beta, f]) if f is not None else beta
    constraints = [J - MARGIN * np.eye(4) >> 0 for J in Js] + ([f >= 0] if f is not None else [])
    fit_term = cp.sum_squares(L @ (theta - estimate))
    prior, scale = _prior_scale(robot)
    weight = regularisation * float(np.trace(G)) / max(G.shape[0], 1)
    prior_term = cp.sum_squares(cp.multiply(1.0 / scale, pi - prior))
    try:  # what no torque depends on: the model's own values (a prior of tiny weight)
        if regularisation <= 0:
            raise InvalidParameterError("regularisation", regularisation, "> 0")
        _solve(cp.Problem(cp.Minimize(fit_term + weight * prior_term), constraints))
    except InvalidParameterError:  # Clarabel failed (noise-free logs: G ~ 1e24): the plain fit, scaled to
        # order 1 (its completion of what no torque depends on is then the solver's)
        unit = np.sqrt(max(float(np.trace(G)) / max(G.shape[0], 1), 1e-300))
        _solve(cp.Problem(cp.Minimize(cp.sum_squares((L / unit) @ (theta - estimate))), constraints))
    standard = np.asarray(pi.value, dtype=float)
    beta_star = np.asarray(base_map.combination @ standard, dtype=float)  # exactly B π: the URDF's β
    f_star = np.maximum(np.asarray(f.value, dtype=float), 0.0) if f is not None else np.zeros(0)
    least = np.array(
        [
            float(
                np.linalg.eigvalsh(
                    pseudo_inertia(standard[N_BODY_PARAMETERS * i : N_BODY_PARAMETERS * (i + 1)])
                )[0]
            )
            for i in range(bodies)
        ]
    )
    return PhysicalFit(np.concatenate([beta_star, f_star]), standard, f_star, least)


def compare_physical(
    log: object, robot: RobotModel, options: object, result: object
) -> tuple[dict[str, Any], list[str], PhysicalFit]:
    """The ``--physical`` part of ``identify``: the unconstrained fit's consistency (which links
    are infeasible, by how much), the constrained fit, and both on the validation period.

    Returns:
        ``(document, lines, fit)``: the JSON part (``"parameters"`` holds the constrained
        estimates with the unconstrained σ, in the rows of ``result.parameters()``), the text,
        and the fit.
    """
    from twolink_pin.identification.least_squares import Identification, IdentificationOptions, validation_of
    from twolink_pin.identification.observation import ParameterSet

    assert isinstance(result, Identification) and isinstance(options, IdentificationOptions)
    if result.gram is None:
        raise InvalidParameterError(
            "physical fit", "no Gram matrix", "an identification with its weighted Gram matrix"
        )
    pset = ParameterSet.of(robot, friction=options.friction)
    nb = pset.base.size
    before = consistency(robot, pset.base, result.estimate[:nb])
    fit = physical_fit(robot, pset.base, result.estimate, result.gram, options.friction)
    after = consistency(robot, pset.base, fit.theta[:nb])
    validations = {
        "unconstrained": result.validation,
        "physical": validation_of(log, robot, fit.theta, options),  # type: ignore[arg-type]
    }
    rms = {k: (None if v is None else v.rms) for k, v in validations.items()}
    rows = result.parameters()
    for row, value in zip(rows, fit.theta):
        row["unconstrained_estimate"] = row["estimate"]
        row["estimate"] = float(value)
    lines = [
        "  physical consistency (pseudo-inertia ⪰ 0, Wensing, Kim & Slotine 2017; friction >= 0; cvxpy + Clarabel):",
        f"    unconstrained fit: {before.describe()}",
        f"    constrained fit:   {after.describe()}; λ_min(J) per link {', '.join(f'{n} {x:.3g}' for n, x in zip(before.links, fit.least_eigenvalue))} kg·m²",
    ]
    changed = [
        (r, r["unconstrained_estimate"])
        for r in rows
        if abs(r["estimate"] - r["unconstrained_estimate"])
        > 1e-9 * max(1.0, abs(r["unconstrained_estimate"]))
    ]
    for row, old in changed:
        lines.append(f"    {row['name'][:44]:44s} {old:14.8g} → {row['estimate']:14.8g} (σ {row['std']:.3g})")
    verdict = None
    if rms["unconstrained"] is not None and rms["physical"] is not None:
        u, p = rms["unconstrained"], rms["physical"]
        total_u, total_p = float(np.sqrt(np.mean(u**2))), float(np.sqrt(np.mean(p**2)))
        if not changed:
            verdict = "same"
            said = "the constraints are inactive: the unconstrained estimate is physical already"
        elif max(total_u, total_p) < 1e-6:
            verdict = "tie"
            said = "both at rounding level (noise-free data)"
        elif abs(total_p - total_u) <= TIE * max(total_u, total_p):
            verdict = "tie"
            said = (
                f"no measurable difference (within {100 * TIE:g} %): the constraints moved the estimate along "
                "directions this motion hardly excites, which only another motion can tell apart"
            )
        else:
            verdict = "physical" if total_p < total_u else "unconstrained"
            said = f"the {verdict} fit predicts better"
        lines.append(
            f"    validation torque RMS per joint: unconstrained {np.array2string(u, precision=4)} N·m, "
            f"physical {np.array2string(p, precision=4)} N·m (overall {total_u:.4g} vs {total_p:.4g}): {said}"
        )
    document = {
        "unconstrained_infeasible_links": list(before.infeasible),
        "unconstrained_least_eigenvalue": dict(zip(before.links, before.least_eigenvalue.tolist())),
        "physical_least_eigenvalue": dict(zip(before.links, fit.least_eigenvalue.tolist())),
        "standard_parameters": fit.standard.tolist(),
        "validation_rms": {k: (None if v is None else v.tolist()) for k, v in rms.items()},
        "better_on_validation": verdict,
        "parameters": rows,
    }
    return document, lines, fit


def nearest_physical(robot: RobotModel, base_map: BaseParameterMap, beta: np.ndarray) -> np.ndarray | None:
    """The standard parameters closest to the model's own (its URDF's; scaled per body by
    :data:`PRIOR_LENGTH`) among those that give ``beta`` exactly with every ``J_i ⪰ MARGIN/2 𝟙``
    (half the fit's margin: a fit on its margin leaves room) — what the data do not fix stays
    what the user's URDF says. None if there are none or the solver is not sure."""
    import cvxpy as cp

    bodies = robot.model.njoints - 1
    prior, scale = _prior_scale(robot)
    Js = [cp.Variable((4, 4), symmetric=True) for _ in range(bodies)]
    pi = cp.hstack([p for J in Js for p in _parameters_of(J)])
    B = base_map.combination
    problem = cp.Problem(
        cp.Minimize(cp.sum_squares(cp.multiply(1.0 / scale, pi - prior))),
        [B @ pi == np.asarray(beta, dtype=float)] + [J - 0.5 * MARGIN * np.eye(4) >> 0 for J in Js],
    )
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.SolverError:
        return None
    if problem.status != cp.OPTIMAL or pi.value is None:
        return None
    value = np.asarray(pi.value, dtype=float)
    return value + np.linalg.pinv(B) @ (beta - B @ value)  # B π = β to rounding


def write_identified_urdf(
    path: str,
    robot: RobotModel,
    estimate: np.ndarray,
    friction: bool,
    fit: PhysicalFit | None = None,
) -> tuple[str, np.ndarray]:
    """Write ``robot``'s URDF with identified inertias (and friction) to ``path``, atomically:
    the base parameters of ``fit`` (``--physical``) or the estimate, completed into the
    standard parameters nearest the URDF's own (:func:`nearest_physical`).

    Returns:
        ``(text, θ)``: the file's text and the θ = (β, V, C) it holds.

    Raises:
        InvalidParameterError: the estimate is physically impossible (the links named: use
            ``--physical``) or on the boundary of the physical set.
    """
    from twolink_pin.files import atomic_write
    from twolink_pin.model.urdf_validation import validate_urdf_string
    from twolink_pin.model.urdf_write import urdf_with_inertias

    pset_base = (
        BaseParameterMap(robot.model)
        if not isinstance(robot.parameter_map, BaseParameterMap)
        else robot.parameter_map
    )
    nb = pset_base.size
    theta = np.asarray(fit.theta if fit is not None else estimate, dtype=float).copy()
    if friction:
        theta[nb:] = np.maximum(theta[nb:], 0.0)
    beta = theta[:nb]
    standard = nearest_physical(robot, pset_base, beta)
    if standard is None and fit is not None:  # a fit on its margin: its own completion (carries the prior)
        standard = fit.standard
    if standard is None:
        check = consistency(robot, pset_base, beta)
        reason = (
            check.describe() if not check.feasible else f"some link within {MARGIN:g} kg·m² of the boundary"
        )
        raise InvalidParameterError(
            "--write-urdf", path, f"physically consistent estimates: {reason} (add --physical)"
        )
    least = min(
        float(
            np.linalg.eigvalsh(pseudo_inertia(standard[N_BODY_PARAMETERS * i : N_BODY_PARAMETERS * (i + 1)]))[
                0
            ]
        )
        for i in range(robot.model.njoints - 1)
    )
    if least < 0.25 * MARGIN:
        raise InvalidParameterError(
            "--write-urdf",
            path,
            f"estimates strictly inside the physical set (λ_min {least:.3g} kg·m²; add --physical)",
        )
    coefficients = (theta[nb : nb + robot.nv], theta[nb + robot.nv :]) if friction else None
    text = urdf_with_inertias(
        robot.urdf_path.read_text(encoding="utf-8"), robot.model, standard, coefficients
    )
    name = catalog_profile_name(robot.profile)
    # given back with --urdf, it runs with the catalog robot's profile; not a profile whose own
    # parameter map constrains the inertias (the twolink's lumped p1..p3 need c_y = 0 exactly,
    # which identified numbers meet only to rounding): that file keeps the generic profile
    if name is not None and robot.profile.parameter_map is None:
        text = declare_profile(text, name)
    validate_urdf_string(text, path)
    with atomic_write(path) as f:
        f.write(text)
    return text, theta
