"""The course report's numbers and choices, as data (imports nothing).

MEEN 612, "Kinematics, Dynamics and Control of a 2-Link Planar Robot" (``shared/reference``).
Values the report prints are claims to check (tests and :mod:`twolink_pin.twolink.errata`
do); where it is silent, the choice we made is here too, marked as ours.
"""

from __future__ import annotations

REPORT_P = {"p1": 3.4, "p2": 0.4, "p3": 0.3}
"""The report's lumped parameters [kg·m²]."""

REPORT_VIA_XY = ((0.48, 0.1), (0.38, 0.0), (0.48, -0.1), (0.58, 0.0), (0.48, 0.1))
"""The report's end-effector via points [m] (its text misprints the third as (0.48, 0.1))."""
REPORT_TIMES = (0.0, 1.0, 2.0, 3.0, 4.0)
"""The report's via-point times [s]."""

Q0_OFFSET = (0.1, -0.1)
"""``q(0) − q_d(0)`` [rad] of our runs (the report does not state its initial state)."""
LAMBDA = 5.0
"""λ [1/s] of the Slotine–Li laws (the report does not state it; our choice)."""

REPORT_FRICTION = ((0.4, 0.2), (0.2, 0.1))
"""The report's joint friction: viscous V [N·m·s/rad], Coulomb C [N·m] per joint."""

ARMATURE = (0.1, 0.1)
"""Rotor inertia reflected through each joint's gearbox [kg·m²]: the report gives no drive data;
ours is the value the MuJoCo Menagerie's Franka Panda model sets on every joint
(``franka_emika_panda/panda.xml``, class ``panda``), an arm of the twolink's size (links of
0.3–0.4 m, joint inertias of 0.4–3.4 kg·m² here). The sim-to-sim section's arm effects (with the
report's friction as MuJoCo's joint damping and dry friction: :data:`REPORT_FRICTION`)."""

REPORT_GAINS: dict[str, dict[str, tuple[float, ...]]] = {
    "pd": {"kp": (350.0, 300.0), "kd": (40.0, 50.0)},
    "computed-torque": {"k": (40.0, 50.0)},
    "robust": {"k": (40.0, 50.0)},
    "adaptive": {"k": (120.0, 120.0), "gamma": (0.5, 0.15, 0.6)},
    "adaptive-friction": {"k": (90.0, 90.0), "gamma": (0.5, 0.15, 0.6, 1.7, 1.4, 2.5, 2.5)},
}
"""The report's gains per law (Kp, Kd [N·m/rad, N·m·s/rad]; K [N·m·s/rad]; γ with
``Γ = diag(1/γ)``, in the order p1, p2, p3, V1, V2, C1, C2)."""

REPORT_CONTROLLERS = ("pd", "computed-torque", "robust", "adaptive", "adaptive-friction")
"""The report's five controllers, in its order."""

REPORT_TABLE1 = {
    (0.48, 0.1): ((-0.2936, 1.3587), (0.7044, -1.3587)),
    (0.38, 0.0): ((-0.6426, 1.8921), (0.6426, -1.8921)),
    "third": ((-0.7044, 1.3587), (0.2936, -1.3587)),
    (0.58, 0.0): ((-0.2835, 0.7424), (0.2835, -0.7424)),
}
"""The report's Table 1 (the third row's coordinates are lost in the text conversion)."""

REPORT_COEFFICIENTS = (
    (-0.2936, 0, 0, 0, -2.04, 3.11, 1.95, 0.65, -0.12, 0.01, -0.00048),
    (1.3587, 0, 0, 0, 3.19, -4.4, 2.32, -0.54, 0.04, 0.003, -0.00051),
)
"""The report's eqs. 6–7, ascending powers of t [s]."""

REPORT_TABLE2: dict[str, tuple[float, float, float, float, float, float]] = {
    "pd": (0.2543, 0.0164, 1.3443, 0.1258, 85.6407, 13.6080),
    "computed-torque": (0.3832, 0.0188, 0.6507, 0.0871, 116.0244, 13.6746),
    "robust": (0.4071, 0.0391, 0.7749, 0.1266, 139.1337, 23.2539),
    "adaptive": (0.0347, 0.0159, 0.0799, 0.0915, 42.1057, 16.9666),
    "adaptive-friction": (0.0212, 0.0025, 0.0533, 0.0804, 39.5083, 14.0296),
}
"""The report's Table 2 "norms" (unspecified) of e1, e2, ė1, ė2, τ1, τ2 over 30 s."""
REPORT_TABLE2_COLUMNS = ("e1", "e2", "edot1", "edot2", "tau1", "tau2")
"""Columns of :data:`REPORT_TABLE2`."""

REPORT_FIGURES: dict[str, dict[str, int]] = {
    "trajectory": {"theta1": 3, "theta2": 4, "workspace": 5, "desired_torque": 6},
    "pd": {"theta1": 7, "theta2": 8, "theta1dot": 9, "theta2dot": 10, "torque": 11},
    "computed-torque": {"theta1": 12, "theta2": 13, "theta1dot": 14, "theta2dot": 15, "torque": 16},
    "robust": {"theta1": 17, "theta2": 18, "theta1dot": 19, "theta2dot": 20, "torque": 21},
    "adaptive": {
        "theta1": 22,
        "theta2": 23,
        "theta1dot": 24,
        "theta2dot": 25,
        "torque": 26,
        "param_error": 27,
    },
    "adaptive-friction": {
        "theta1": 28,
        "theta2": 29,
        "theta1dot": 30,
        "theta2dot": 31,
        "param_error": 32,
        "friction_error": 33,
        "torque": 34,
    },
}
"""The report's figure number of each of our figures (shown in their titles)."""
