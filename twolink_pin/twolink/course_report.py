"""The course report's sections of ``twolink-pin report``: the hook the twolink's profile
declares (:class:`~twolink_pin.model.profile.ReportSections`).

The report asks the robot's profile for its sections instead of testing its name; for the
twolink they are the closed-form check, the equations derived from the URDF written in the
course's p beside its formulas, Table 1 and Table 2 beside ours, the errata, and
the identification section beside Fig. 27 (:mod:`twolink_pin.twolink.report_identification`).
Imported with the profile when the package is imported: what it needs is imported when
called.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

ANIMATED_LAW = "adaptive"
"""The law whose run the twolink's report animates."""
REUSED_LAW = "adaptive"
"""The law whose report run is the identification section's run along the report's trajectory."""


class CourseReport:
    """The twolink's report sections (stateless: the profile holds one instance)."""

    def steps(self, options: Any, laws: Sequence[str]) -> int:
        """One progress step: the identification section, when it is shown (:func:`shows_identification`)."""
        return 1 if shows_identification(options, laws) else 0

    def submit(self, pool: Any, options: Any, fig_dir: str, laws: Sequence[str]) -> Any:
        """The identification section's tasks (the longest: 3 adaptive runs and a logged
        run), submitted first so that the laws' runs fill the other workers meanwhile."""
        if not shows_identification(options, laws):
            return None
        from twolink_pin.twolink import report_identification as ident

        reused = REUSED_LAW in laws and ident._reuses_adaptive_run(options)
        return reused, ident._submit_identification(pool, options, fig_dir, reused)

    def facts(self, robot: Any, via: Any) -> dict[str, Any]:
        """The closed-form check, the derived equations beside the report's, Table 1 (None for
        another trajectory) and the report's printed p, coefficients and Table 2."""
        from twolink_pin.twolink.reference import (
            REPORT_COEFFICIENTS,
            REPORT_P,
            REPORT_TABLE2,
            REPORT_TABLE2_COLUMNS,
        )

        return {
            "closed_form_check": closed_form_check(robot),
            "course_equations": course_equations_check(robot),
            "table1": None if via is None else table1(robot, via),
            "report_p": REPORT_P,
            "report_coefficients": [list(c) for c in REPORT_COEFFICIENTS],
            "report_table2": {n: list(v) for n, v in REPORT_TABLE2.items()},
            "report_table2_columns": list(REPORT_TABLE2_COLUMNS),
        }

    def reads(self, laws: Sequence[str]) -> Sequence[str]:
        """The report's own adaptive run, when it runs (the identification section's run along
        the report's trajectory)."""
        return (REUSED_LAW,) if REUSED_LAW in laws else ()

    def collect(
        self, pending: Any, robot: Any, options: Any, fig_dir: str, runs: Mapping[str, Any]
    ) -> dict[str, Any] | None:
        """The identification section from :meth:`submit`'s tasks; the report's own
        adaptive run is the run along its trajectory when it is the same run."""
        if pending is None:
            return None
        from twolink_pin import interrupts
        from twolink_pin.twolink import report_identification as ident

        reused, (runs_future, fit_future) = pending
        heard = len(interrupts.received)  # a signal from here on stops the waits (result_of)
        excitation_runs = {key: interrupts.result_of(f, heard) for key, f in runs_future.items()}
        if reused and REUSED_LAW in runs:
            result = runs[REUSED_LAW]
            assert result.p_hat is not None
            own = (np.asarray(result.t), np.asarray(result.p_hat)[:, : np.asarray(robot.p).size])
            excitation_runs = {"report": own, **excitation_runs}
        section = ident._identification_section(
            options,
            fig_dir,
            excitation_runs,
            None if fit_future is None else interrupts.result_of(fit_future, heard),
        )
        section["beside_law"] = REUSED_LAW  # the page shows it after this law's section (Fig. 27's)
        return section

    def errata(
        self,
        robot: Any,
        trajectory: Any,
        runs: Mapping[str, Any],
        specs: Mapping[str, str],
        options: Any,
        q0_offset: Any,
        lams: Mapping[str, float],
    ) -> list[dict[str, Any]]:
        """Where the course report is wrong or silent, with the evidence of these runs."""
        from twolink_pin.run_spec import make_scenario
        from twolink_pin.scenario import law_class
        from twolink_pin.trajectory import default_trajectory
        from twolink_pin.twolink import errata
        from twolink_pin.twolink.reference import LAMBDA

        lam = next(iter(lams.values()), LAMBDA)
        report_trajectory = default_trajectory(robot)  # the errata are about the report's own trajectory
        items = [
            errata.third_via_point(robot),
            errata.printed_coefficients(report_trajectory),
            errata.y3_sign(robot),
        ]
        items.append(errata.unstated_settings(lam, tuple(np.asarray(q0_offset).tolist())))
        if "robust" in runs:
            items.append(errata.robust_naming(runs["robust"]))
        if "adaptive" in runs:
            cls = law_class(specs["adaptive"])
            controller = make_scenario(cls, robot, lam=options.run.lam).controller
            items.append(errata.parameter_convergence(runs["adaptive"], controller, trajectory))  # type: ignore[arg-type]
        return [e._asdict() for e in items]


def shows_identification(options: Any, laws: Sequence[str]) -> bool:
    """Whether the report has the identification section: asked for (``options.identification``)
    and one of its ``laws`` (laws or variants) estimates the inertial parameters — the section
    answers a question about such a law (why its p̂ is still far from p at the end of the run),
    which a report of ``mpc`` and ``pd`` does not raise."""
    from twolink_pin.law_variant import parse_variant
    from twolink_pin.scenario import law_class

    if not options.identification:
        return False
    return any("inertial" in law_class(parse_variant(text).law).estimates for text in laws)


def closed_form_check(robot: Any, samples: int = 1000) -> dict[str, Any]:
    """Largest difference between Pinocchio's M, C and the report's closed form."""
    from twolink_pin.dynamics import coriolis_matrix, mass_matrix
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


def course_equations_check(robot: Any) -> dict[str, Any]:
    """The equations derived from the URDF written in the p they find, beside the report's
    (:func:`twolink_pin.twolink.course_equations.course_check`)."""
    from twolink_pin.symbolic import derive_equations
    from twolink_pin.twolink.course_equations import course_check

    return course_check(derive_equations(robot))


def table1(robot: Any, via: Any) -> list[dict[str, Any]]:
    """Our inverse kinematics of the report's via points beside its Table 1."""
    from twolink_pin.kinematics import inverse_kinematics
    from twolink_pin.twolink.reference import REPORT_TABLE1

    rows = []
    for xy, report in zip(via.xy[:4], REPORT_TABLE1.values()):
        ours = inverse_kinematics(robot, xy)
        rows.append({"xy": list(xy), "ours": ours.tolist(), "report": [list(r) for r in report]})
    return rows
