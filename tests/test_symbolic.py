"""The equations derived in closed form (twolink_pin.symbolic) against a second method:
Pinocchio's CRBA, Coriolis matrix, gravity, regressor and RNEA at random states on every kind
of arm the derivation accepts; the numerical base parameters; the course report's formulas;
and identities (Ṁ − 2C skew-symmetric, the trigonometric rewriting)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.model import load_robot
from twolink_pin.model.base_parameters import BaseParameterMap
from twolink_pin.symbolic import Equations, derive_equations, first_joints
from twolink_pin.symbolic.numpy_module import numpy_module

FIXTURES = Path(__file__).parent / "fixtures"
RELATIVE = 1e-10
"""Largest difference from Pinocchio, relative to the largest entry of Pinocchio's term (or 1)."""
ARMS: dict[str, tuple[str, float, int | None]] = {
    "twolink": ("twolink", 0.0, None),
    "twolink-payload": ("twolink", 1.5, None),
    "double_pendulum": ("double_pendulum", 0.0, None),
    "asr_twodof": ("asr_twodof", 0.0, None),
    "ur5-3": ("ur5", 0.0, 3),
    "rpr": (str(FIXTURES / "rpr_arm.urdf"), 0.5, None),
    "branching": (str(FIXTURES / "branching_arm.urdf"), 0.0, None),
}
"""Arms of every kind it accepts: planar, vertical, spatial with quarter-turn placements (the
UR5's first three joints), a prismatic joint behind a tilted placement, an unaligned axis, a
folded fixed joint and a payload (``rpr_arm.urdf``), and a tree of two branches
(``branching_arm.urdf``)."""


class Arm:
    """One arm: its Pinocchio model, its derived equations and their numpy module."""

    def __init__(self, tmp: Path, name: str) -> None:
        robot_name, payload, joints = ARMS[name]
        self.robot = load_robot(robot_name, payload=payload)
        self.model = self.robot.model if joints is None else first_joints(self.robot.model, joints)
        self.data = self.model.createData()
        self.eq: Equations = derive_equations(self.robot, joints=joints, use_cache=False)
        path = tmp / f"{name.replace('-', '_')}_equations.py"
        path.write_text(numpy_module(self.eq, robot_name), encoding="utf-8")
        spec = importlib.util.spec_from_file_location(path.stem, path)
        assert spec is not None and spec.loader is not None
        self.module: ModuleType = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(self.module)
        self.path = path


@pytest.fixture(scope="module")
def arms(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Arm]:
    tmp = tmp_path_factory.mktemp("equations")
    return {name: Arm(tmp, name) for name in ARMS}


def _close(ours: np.ndarray, theirs: np.ndarray, what: str, floor: float = 1.0) -> None:
    """Within :data:`RELATIVE` of the larger of ``theirs`` and ``floor`` (the arm's torque scale:
    a URDF's quarter turn written to 11 digits is exact in the derivation, not in Pinocchio,
    so a term that vanishes at one state differs by the angle's error times the arm's size)."""
    scale = max(floor, float(np.abs(theirs).max()))
    assert float(np.abs(ours - theirs).max()) <= RELATIVE * scale, (what, ours, theirs)


def _state(arm: Arm, draw: Any) -> tuple[np.ndarray, ...]:
    lower = np.maximum(arm.model.lowerPositionLimit, -np.pi)
    upper = np.minimum(arm.model.upperPositionLimit, np.pi)
    unit = st.floats(0.0, 1.0)
    q = lower + np.array([draw(unit) for _ in range(arm.model.nv)]) * (upper - lower)
    v, a, w = (np.array([draw(st.floats(-5.0, 5.0)) for _ in range(arm.model.nv)]) for _ in range(3))
    return q, v, a, w


@pytest.mark.parametrize("name", list(ARMS))
@settings(max_examples=25, deadline=None)
@given(draw=st.data())
def test_the_module_gives_pinocchios_terms_at_random_states(
    arms: dict[str, Arm], name: str, draw: Any
) -> None:
    """M = crba, C = computeCoriolisMatrix (so C is Pinocchio's Christoffel factorisation), g =
    computeGeneralizedGravity, Y p_base = RNEA, and Y(q, v, a, w) p_base = M a + C(q, v) w + g:
    each to 1e-10 relative (Y against computeJointTorqueRegressor: the next test)."""
    arm = arms[name]
    q, v, a, w = _state(arm, draw.draw)
    model, data, module = arm.model, arm.data, arm.module
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    C = pin.computeCoriolisMatrix(model, data, q, v).copy()
    g = pin.computeGeneralizedGravity(model, data, q).copy()
    # the arm's gravity torque at its neutral pose [N·m]: the UR5's 59 N·m at the shoulder,
    # where q2 = π/2 leaves 3e-10 N·m (its URDF's 1.570796325 rad against π/2 in the derivation)
    size = max(1.0, float(np.abs(pin.computeGeneralizedGravity(model, data, pin.neutral(model))).max()))
    _close(module.M(q), M, "M")
    _close(module.C(q, v), C, "C")
    _close(module.g(q), g, "g", size)
    _close(module.Y(q, v, a) @ module.p_base, pin.rnea(model, data, q, v, a), "Y p = RNEA", size)
    _close(module.Y(q, v, a, w) @ module.p_base, M @ a + C @ w + g, "Y(q, v, a, w) p", size)


@pytest.mark.parametrize("name", list(ARMS))
def test_the_base_parameters_are_the_numerical_maps(arms: dict[str, Arm], name: str) -> None:
    """The exact regrouping keeps the standard parameters Gautier's numerical QR keeps, and its
    combinations have the same values (BaseParameterMap rounds its coefficients to 12 digits);
    the derived regressor is Pinocchio's regressor times the numerical map's P."""
    arm = arms[name]
    numeric = BaseParameterMap(arm.model)
    assert [str(b) for b in arm.eq.beta] == [f"beta{k}" for k in range(1, numeric.size + 1)]
    np.testing.assert_allclose(arm.eq.beta_values, numeric.values(arm.model), rtol=1e-9, atol=1e-12)
    rng = np.random.default_rng(3)
    q, v, a = rng.uniform(-2, 2, (3, arm.model.nv))
    Y_pi = pin.computeJointTorqueRegressor(arm.model, arm.data, q, v, a)
    np.testing.assert_allclose(arm.module.Y(q, v, a), Y_pi @ numeric.matrix, rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", list(ARMS))
def test_mdot_minus_2c_is_skew_symmetric(arms: dict[str, Arm], name: str) -> None:
    """Checked exactly by the derivation, and numerically here: Ṁ by a central difference of
    the module's M along q̇, N = Ṁ − 2C, N + Nᵀ ≈ 0 (1e-6: the difference's error)."""
    arm = arms[name]
    assert arm.eq.skew_symmetric
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, v = rng.uniform(-1.5, 1.5, (2, arm.model.nv))
        h = 1e-6
        Mdot = (arm.module.M(q + h * v) - arm.module.M(q - h * v)) / (2 * h)
        N = Mdot - 2 * arm.module.C(q, v)
        assert np.abs(N + N.T).max() < 1e-6 * max(1.0, np.abs(Mdot).max())


def test_the_twolink_equations_are_the_course_reports(arms: dict[str, Arm]) -> None:
    """Written in the parameters they find (p1 = β1 + β4, p2 = β4, p3 = l2x β2), the derived M,
    C and Slotine–Li regressor are the report's, symbolically; p so found, in masses and
    lengths, is the report's p1 = Izz1 + m1 c1² + m2 L1² + p2, p2 = Izz2 + m2 c2², p3 = m2 L1 c2;
    and its values are the twolink's lumped map (3.4, 0.4, 0.3), and with a payload too."""
    from twolink_pin.twolink.course_equations import course_check

    for name in ("twolink", "twolink-payload"):
        arm = arms[name]
        check = course_check(arm.eq)
        assert check["found"] == {"p1": "beta1 + beta4", "p2": "beta4", "p3": "beta2*l2x"}
        assert check["M"] and check["C"] and check["Y"] and check["p_expressions"]
        np.testing.assert_allclose(list(check["p_values"].values()), arm.robot.p, rtol=1e-12)


def test_the_twolink_module_agrees_with_the_closed_form(arms: dict[str, Arm]) -> None:
    """The numpy module against the report's closed form typed in closed_form.py (kept as the
    independent check): M, C and the Slotine–Li regressor in p at random states."""
    from twolink_pin.twolink import closed_form

    arm = arms["twolink"]
    beta = arm.module.p_base
    rng = np.random.default_rng(7)
    for _ in range(20):
        q, v, w, a = rng.uniform(-3, 3, (4, 2))
        np.testing.assert_allclose(
            arm.module.M(q), closed_form.mass_matrix(q, arm.robot.p), rtol=0, atol=1e-12
        )
        np.testing.assert_allclose(
            arm.module.C(q, v), closed_form.coriolis_matrix(q, v, arm.robot.p), atol=1e-12
        )
        np.testing.assert_allclose(
            arm.module.Y(q, v, a, w) @ beta, closed_form.regressor(q, v, w, a) @ arm.robot.p, atol=1e-12
        )


def test_the_course_check_can_fail(tmp_path: Path) -> None:
    """An arm the report's three parameters cannot describe (link 2's centre of mass off its
    x axis: M gains sin q2 terms) finds no p; the course's M itself is not the derived one
    with p3's sign flipped."""
    import sympy as sp

    from twolink_pin.twolink.course_equations import course_matrices, course_parameters

    text = (Path(__file__).parents[1] / "robots" / "twolink.urdf").read_text(encoding="utf-8")
    mass = '\n      <mass value="6.578947368421052"/>'
    moved = text.replace(
        '<origin xyz="0.12 0 0" rpy="0 0 0"/>' + mass, '<origin xyz="0.12 0.03 0" rpy="0 0 0"/>' + mass
    )
    assert moved != text
    path = tmp_path / "offset.urdf"
    path.write_text(moved, encoding="utf-8")
    eq = derive_equations(load_robot(str(path)), use_cache=False)
    assert course_parameters(eq) is None
    twolink = derive_equations(load_robot(), use_cache=False)
    course = course_matrices(twolink.q, twolink.dq, twolink.ddq, twolink.w)
    p1, p2, p3 = course["p"]
    flipped = {
        twolink.beta[0]: p1 - p2,
        twolink.beta[3]: p2,
        twolink.beta[1]: -p3 / sp.Symbol("l2x", real=True),
    }
    wrong = twolink.shown(twolink.M).xreplace(flipped)
    assert sp.simplify(wrong - course["M"]) != sp.zeros(2, 2)


def test_the_twolink_text_shows_the_course_form(arms: dict[str, Arm]) -> None:
    """The lines a person reads: M and C of the twolink in its base parameters."""
    from twolink_pin.symbolic.formats import equations_text

    text = equations_text(arms["twolink"].eq)
    for line in (
        "  β1 = Izz1 + m2*l2x**2 = 3 kg·m²",
        "  M11 = β1 + β4 + 2*β2*l2x*cos(q2)",
        "  M12 = β4 + β2*l2x*cos(q2)",
        "  M22 = β4",
        "  C11 = -β2*q̇2*l2x*sin(q2)",
        "  C12 = -β2*l2x*(q̇1 + q̇2)*sin(q2)",
        "  C21 = β2*q̇1*l2x*sin(q2)",
        "  C22 = 0",
    ):
        assert line in text.splitlines(), (line, text)


def test_the_module_needs_no_twolink_pin_and_takes_batches(arms: dict[str, Arm]) -> None:
    """The written module imports numpy only (run in a fresh interpreter: no twolink_pin, no
    sympy, no pinocchio loaded); a batch gives each state's result; bad shapes are refused
    with a message naming the argument."""
    arm = arms["ur5-3"]
    source = arm.path.read_text(encoding="utf-8")
    assert "twolink_pin" not in source.split('"""', 2)[2]
    code = (
        "import importlib.util, json, sys\n"
        f"spec = importlib.util.spec_from_file_location('m', {str(arm.path)!r})\n"
        "m = importlib.util.module_from_spec(spec); spec.loader.exec_module(m)\n"
        "import numpy as np\n"
        "q = np.array([0.1, -0.4, 0.9]); v = np.array([0.3, 0.2, -0.1]); a = np.array([1.0, -2.0, 0.5])\n"
        "print(json.dumps({'tau': (m.Y(q, v, a) @ m.p_base).tolist(), "
        "'loaded': sorted(k for k in sys.modules if k.split('.')[0] in ('twolink_pin', 'sympy', 'pinocchio'))}))\n"
    )
    done = subprocess.run(
        [sys.executable, "-I", "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    import json

    result = json.loads(done.stdout)
    assert result["loaded"] == []
    q, v, a = np.array([0.1, -0.4, 0.9]), np.array([0.3, 0.2, -0.1]), np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(result["tau"], pin.rnea(arm.model, arm.data, q, v, a), rtol=0, atol=1e-9)
    rng = np.random.default_rng(11)
    Q, V, A = rng.uniform(-2, 2, (3, 7, 3))
    m = arm.module
    np.testing.assert_array_equal(m.M(Q)[4], m.M(Q[4]))
    np.testing.assert_array_equal(m.C(Q, V)[2], m.C(Q[2], V[2]))
    np.testing.assert_array_equal(m.g(Q)[6], m.g(Q[6]))
    np.testing.assert_array_equal(m.Y(Q, V, A)[5], m.Y(Q[5], V[5], A[5]))
    np.testing.assert_array_equal(m.M(list(Q[1])), m.M(Q[1]))
    out = np.empty((3, 3))
    assert m.M(Q[0], out=out) is out and np.array_equal(out, m.M(Q[0]))
    np.testing.assert_allclose(m.M(Q[0], p=2 * m.p_base), 2 * m.M(Q[0]), rtol=1e-12)
    with pytest.raises(ValueError, match=r"q must have shape \(3,\) or \(N, 3\), got \(2,\)"):
        m.M(np.zeros(2))
    with pytest.raises(ValueError, match="p must have shape"):
        m.M(Q[0], p=np.zeros(2))
    with pytest.raises(ValueError, match="out must be a float array of shape"):
        m.M(Q[0], out=np.empty((2, 2)))


@settings(max_examples=40, deadline=None)
@given(
    terms=st.lists(
        st.tuples(
            st.integers(-3, 3), st.integers(0, 3), st.integers(0, 3), st.integers(0, 3), st.integers(0, 3)
        ),
        min_size=1,
        max_size=6,
    ),
    angles=st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)),
)
def test_the_readable_form_is_the_same_function(
    terms: list[tuple[int, ...]], angles: tuple[float, float]
) -> None:
    """A polynomial in cos and sin of two angles, reduced and rewritten as a sum of cos(f·q) and
    sin(f·q) (product-to-sum), has the polynomial's value at any angles."""
    import math

    import sympy as sp

    from twolink_pin.symbolic.readable import to_expr
    from twolink_pin.symbolic.trig_ring import REVOLUTE, TrigRing

    ring = TrigRing([REVOLUTE, REVOLUTE], [])
    c1, s1, c2, s2 = ring.cos(1), ring.sin(1), ring.cos(2), ring.sin(2)
    p = ring.zero
    value = 0.0
    x, y = angles
    for k, a, b, c, d in terms:
        p += k * c1**a * s1**b * c2**c * s2**d
        value += k * math.cos(x) ** a * math.sin(x) ** b * math.cos(y) ** c * math.sin(y) ** d
    q = sp.symbols("q1 q2", real=True)
    expr = to_expr(ring, ring.reduce(p), {}, q)
    assert abs(float(expr.subs({q[0]: x, q[1]: y})) - value) <= 1e-9 * max(1.0, abs(value))
    assert ring.reduce(p) == ring.reduce(ring.reduce(p) * (c1**2 + s1**2))  # s² = 1 − c² is used


@pytest.mark.slow
def test_the_whole_ur5_at_random_states(tmp_path: Path) -> None:
    """The largest arm it derives (MAX_JOINTS = 6): the UR5's M, C, g and RNEA to 1e-10 relative."""
    robot = load_robot("ur5")
    eq = derive_equations(robot, use_cache=False)
    path = tmp_path / "ur5_equations.py"
    path.write_text(numpy_module(eq), encoding="utf-8")
    spec = importlib.util.spec_from_file_location("ur5_equations", path)
    assert spec is not None and spec.loader is not None
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    model, data = robot.model, robot.create_data()
    rng = np.random.default_rng(13)
    for _ in range(10):
        q, v, a = rng.uniform(-3, 3, (3, 6))
        M = pin.crba(model, data, q)
        _close(m.M(q), np.triu(M) + np.triu(M, 1).T, "M")
        _close(m.C(q, v), pin.computeCoriolisMatrix(model, data, q, v), "C")
        _close(m.g(q), pin.computeGeneralizedGravity(model, data, q), "g")
        _close(m.Y(q, v, a) @ m.p_base, pin.rnea(model, data, q, v, a), "RNEA")
