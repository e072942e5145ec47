"""The numbers the report shows that are not simulations: the model, the torque check,
the twolink's closed-form check and Table 1, the software versions."""

from __future__ import annotations

import importlib.metadata
import os
import platform
from typing import Any

import numpy as np

from twolink_pin.dynamics import coriolis_matrix, mass_matrix
from twolink_pin.feasibility import TorqueCheck
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.model import RobotModel
from twolink_pin.trajectory import ViaPoints


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
    }


def twolink_closed_form_check(robot: RobotModel, samples: int = 1000) -> dict[str, Any]:
    """Largest difference between Pinocchio's M, C and the report's closed form (twolink)."""
    from twolink_pin.twolink.closed_form import coriolis_matrix as cf_coriolis
    from twolink_pin.twolink.closed_form import mass_matrix as cf_mass

    rng = np.random.default_rng(0)
    data = robot.create_data()
    dev_m, dev_c = 0.0, 0.0
    for _ in range(samples):
        q = rng.uniform(-np.pi, np.pi, robot.nv)
        v = rng.uniform(-5, 5, robot.nv)
        dev_m = max(dev_m, float(np.abs(mass_matrix(robot.model, data, q) - cf_mass(q, robot.p)).max()))
        dev_c = max(
            dev_c, float(np.abs(coriolis_matrix(robot.model, data, q, v) - cf_coriolis(q, v, robot.p)).max())
        )
    return {"states": samples, "max_abs_dM": dev_m, "max_abs_dC": dev_c}


def table1(robot: RobotModel, via: ViaPoints) -> list[dict[str, Any]]:
    """Our inverse kinematics of the report's via points beside its Table 1 (twolink)."""
    from twolink_pin.twolink.reference import REPORT_TABLE1

    rows = []
    for xy, report in zip(via.xy[:4], REPORT_TABLE1.values()):
        ours = inverse_kinematics(robot, xy)
        rows.append({"xy": list(xy), "ours": ours.tolist(), "report": [list(r) for r in report]})
    return rows


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
