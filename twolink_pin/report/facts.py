"""The numbers every robot's report shows that are not simulations: the model and its
equations of motion derived in closed form, the torque check, the software versions (the
twolink's closed-form check, its equations beside the course's and Table 1 are its profile's
sections: :mod:`twolink_pin.twolink.course_report`)."""

from __future__ import annotations

import importlib.metadata
import os
import platform
from typing import Any

import numpy as np

from twolink_pin.feasibility import TorqueCheck
from twolink_pin.model import RobotModel


def _finite_or_none(values: Any) -> list[float | None]:
    return [float(x) if np.isfinite(x) else None for x in np.asarray(values, dtype=float)]


def model_facts(robot: RobotModel) -> dict[str, Any]:
    """Sizes, link inertias and the parameters ``p`` of ``robot``."""
    links = []
    for j in range(1, robot.model.njoints):
        inertia = robot.model.inertias[j]
        links.append(
            {
                "joint": robot.model.names[j],
                "mass_kg": float(inertia.mass),
                "com_m": inertia.lever.tolist(),
                "inertia_com_diag_kgm2": np.diag(inertia.inertia).tolist(),
            }
        )
    return {
        "name": robot.name,
        "description": robot.profile.description,
        "urdf": str(robot.urdf_path),
        "nq": robot.nq,
        "nv": robot.nv,
        "gravity_m_s2": robot.model.gravity.linear.tolist(),
        "link_lengths_m": robot.link_lengths.tolist(),
        "torque_limits_Nm": _finite_or_none(robot.torque_limits),
        "payload_kg": robot.payload,
        "links": links,
        "parameters": dict(zip(robot.parameter_map.names, robot.p.tolist())),
        "parameter_units": dict(zip(robot.parameter_map.names, robot.parameter_map.units)),
        "equations": equations_facts(robot),
    }


REPORT_EQUATIONS_JOINTS = 3
"""The report shows the derived equations of an arm of at most this many joints (a 4-joint
arm's C alone runs to pages; ``twolink-pin equations`` writes any arm's)."""


def equations_facts(robot: RobotModel) -> dict[str, Any]:
    """The arm's equations of motion derived in closed form (:mod:`twolink_pin.symbolic`), as
    LaTeX: the base parameters, M (upper triangle), C and g; or why they are not shown."""
    from twolink_pin.errors import EquationsError
    from twolink_pin.symbolic import derive_equations
    from twolink_pin.symbolic.formats import latex_entry

    command = f"twolink-pin equations --robot {robot.urdf_path}"
    if robot.nv > REPORT_EQUATIONS_JOINTS:
        return {"shown": False, "reason": f"{robot.nv} joints: too long to show here ({command} writes them)"}
    try:
        eq = derive_equations(robot)
    except EquationsError as exc:
        return {"shown": False, "reason": str(exc)}
    n = eq.n
    M, C, g = eq.shown(eq.M), eq.shown(eq.C), eq.shown(eq.g)
    return {
        "shown": True,
        "base_parameters": [
            {"latex": rf"\beta_{{{k + 1}}} = {latex_entry(eq, d)}", "value": float(v), "unit": u}
            for k, (d, v, u) in enumerate(zip(eq.beta_definitions, eq.beta_values, eq.beta_units))
        ],
        "zero": [f"β{k + 1}" for k in eq.zero_parameters],
        "lengths_m": dict(eq.lengths),
        "M": [rf"M_{{{r + 1}{c + 1}}} = {latex_entry(eq, M[r, c])}" for r in range(n) for c in range(r, n)],
        "C": [rf"C_{{{r + 1}{c + 1}}} = {latex_entry(eq, C[r, c])}" for r in range(n) for c in range(n)],
        "g": [rf"g_{{{r + 1}}} = {latex_entry(eq, g[r])}" for r in range(n)],
        "skew_symmetric": eq.skew_symmetric,
        "seconds": eq.seconds,
        "from_cache": eq.from_cache,
        "command": command,
    }


def torque_facts(check: TorqueCheck) -> dict[str, Any]:
    """The torque check's peaks, times, limits and verdict."""
    return {
        "peak_Nm": check.peak.tolist(),
        "peak_time_s": check.peak_time.tolist(),
        "limits_Nm": _finite_or_none(check.limits),
        "margin_Nm": _finite_or_none(check.margin),
        "within_limits": check.within_limits,
        "verdict": check.verdict(),
    }


def versions() -> dict[str, str]:
    """Versions of what made the report."""
    import pinocchio

    from twolink_pin.version import __version__

    return {
        "twolink_pin": __version__,
        "pinocchio": pinocchio.__version__,
        "numpy": np.__version__,
        "matplotlib": importlib.metadata.version("matplotlib"),  # plotting is the only importer
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpus": str(os.cpu_count()),
    }
