"""A law's state of any kind, and matrix gains.

* a law that declares an integrator state: its names and units reach the result, the
  recorded state is ``∫ e dt`` (checked against the trapezoidal integral of the recorded
  error), a batch's final state equals the single runs', the state survives save/load;
* the adaptive law's estimates are still ``p_hat`` and now also ``state``;
* matrix gains: a number is ``s I``, numbers a diagonal, a matrix must be symmetric
  positive definite (the error names the field and says why), ``(N, k, k)`` is per run, and
  the law's torque with a matrix gain equals the same law written with the matrix product.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest_sim import ROBOT, TRAJECTORY

from twolink_pin.controllers import (
    Adaptive,
    Controller,
    Gains,
    LawInput,
    LawOutput,
    StateVariable,
    Terms,
    gain,
)
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant import Plant
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.simulation.storage import load_result, save_result
from twolink_pin.studies.batch import simulate_batch


@dataclass(frozen=True, eq=False)
class MatrixGains(Gains):
    kp: Any = gain(((300.0, 20.0), (20.0, 250.0)), per="joint", matrix=True, unit="N·m/rad")
    kd: Any = gain(40.0, per="joint", matrix=True, unit="N·m·s/rad")
    ki: Any = gain(50.0, per="joint", unit="N·m/(rad·s)")


class IntegralLaw(Controller[MatrixGains], register=False):
    """τ = M̂ q̈_d + Ĉ q̇_d + ĝ − Kp e − Kd ė − ki ∫e, with matrix Kp, Kd and state ∫e."""

    name = "integral-test"
    title = "test"
    Gains = MatrixGains

    def state_variables(self) -> tuple[StateVariable, ...]:
        return super().state_variables() + tuple(
            StateVariable(f"I{j + 1}", "rad·s", "integral") for j in range(self.robot.nv)
        )

    def initial_state(self) -> np.ndarray:
        return np.full(self.robot.nv, 0.01)

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        g = self.gains
        e, edot = x.q - x.q_des, x.v - x.v_des
        tau = (
            terms.model(x.q, x.v, x.v_des, x.a_des) - np.matvec(g.kp, e) - np.matvec(g.kd, edot) - g.ki * x.z
        )
        return LawOutput(tau, e)


SHORT = SimulationConfig(duration=0.5)


def test_declared_state_is_recorded_with_names_units_and_values(tmp_path: Path) -> None:
    law = IntegralLaw(ROBOT)
    result = simulate(law, Plant(ROBOT), TRAJECTORY, SHORT)
    assert result.state_names == ("I1", "I2") and result.state_units == ("rad·s", "rad·s")
    assert result.p_hat is None and result.parameter_names == ()
    assert result.state is not None and result.state.shape == (len(result.t), 2)
    np.testing.assert_allclose(result.state[0], 0.01)
    e = result.e
    trapezoid = 0.01 + np.concatenate([[0.0], np.cumsum(0.5 * (e[1:] + e[:-1]), axis=0)[:, 0]]) * result.dt
    np.testing.assert_allclose(result.state[:, 0], trapezoid, atol=1e-6)
    path = save_result(result, tmp_path / "run.npz")
    loaded = load_result(path)
    assert loaded.state_names == result.state_names and loaded.state_units == result.state_units
    np.testing.assert_array_equal(loaded.state, result.state)


def test_batch_state_equals_single_runs() -> None:
    kd = np.stack([40.0 * np.eye(2), np.array([[30.0, 5.0], [5.0, 45.0]])])
    law = IntegralLaw(ROBOT, MatrixGains(kd=kd))
    assert law.runs == 2
    batch = simulate_batch(law, Plant(ROBOT), TRAJECTORY, SHORT, threads=1, record=True)
    assert batch.state_names == ("I1", "I2") and batch.p_hat_final is None
    assert batch.state is not None and batch.state_final is not None
    for r in range(2):
        single = simulate(IntegralLaw(ROBOT, MatrixGains(kd=kd[r])), Plant(ROBOT), TRAJECTORY, SHORT)
        assert single.state is not None
        np.testing.assert_allclose(batch.state_final[r], single.state[-1], rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.state[r], single.state, rtol=0, atol=1e-12)


def test_adaptive_estimates_are_state_and_p_hat() -> None:
    law = Adaptive(ROBOT)
    assert [v.kind for v in law.state_variables()] == ["inertial"] * 3
    result = simulate(law, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.05))
    assert result.state_names == result.parameter_names == ("p1", "p2", "p3")
    np.testing.assert_array_equal(result.state, result.p_hat)


def test_matrix_gain_forms() -> None:
    law = IntegralLaw(ROBOT, MatrixGains(kp=(300.0, 250.0), kd=7.0))
    np.testing.assert_array_equal(law.gains.kp, np.diag([300.0, 250.0])[None])
    np.testing.assert_array_equal(law.gains.kd, 7.0 * np.eye(2)[None])
    assert law.runs is None
    per_run = IntegralLaw(ROBOT, MatrixGains(kd=np.array([[7.0], [9.0]])))
    np.testing.assert_array_equal(per_run.gains.kd, np.stack([7.0 * np.eye(2), 9.0 * np.eye(2)]))
    assert per_run.runs == 2


@pytest.mark.parametrize(
    ("value", "why"),
    [
        (((300.0, 20.0), (21.0, 250.0)), "not symmetric"),
        (((1.0, 2.0), (2.0, 1.0)), "not positive definite"),
        ((-1.0, 2.0), "symmetric positive-definite"),
        (((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), "shape"),
        ("stiff", "symmetric positive-definite"),
    ],
)
def test_matrix_gain_errors_name_the_field_and_the_reason(value: Any, why: str) -> None:
    with pytest.raises(InvalidParameterError, match=why) as info:
        MatrixGains(kp=value)
    assert "kp" in str(info.value)


def test_matrix_gain_of_the_wrong_size_is_refused() -> None:
    with pytest.raises(InvalidParameterError, match=r"kp.*\(2, 2\)"):
        IntegralLaw(ROBOT, MatrixGains(kp=np.eye(3)))
    with pytest.raises(InvalidParameterError, match=r"kp\[1\].*not positive definite"):
        MatrixGains(kp=np.stack([np.eye(2), -np.eye(2)]))


def test_a_matrix_gain_is_a_matrix_product() -> None:
    """The law with a full Kp against the same torque written by hand."""
    kp = np.array([[300.0, 20.0], [20.0, 250.0]])
    law = IntegralLaw(ROBOT)
    from twolink_pin.simulation import terms_for

    terms = terms_for(law)
    rng = np.random.default_rng(0)
    q, v, qd, vd, ad, z = (rng.normal(size=(1, 2)) for _ in range(6))
    tau = law.compute(LawInput(0.0, q, v, z, qd, vd, ad), terms).tau
    expected = terms.model(q, v, vd, ad) - (q - qd) @ kp.T - 40.0 * (v - vd) - 50.0 * z
    np.testing.assert_allclose(tau, expected, rtol=1e-12, atol=1e-12)


def test_the_laws_state_gets_its_own_figure_with_its_names_and_units() -> None:
    from twolink_pin.plotting.run import _simulation_figures

    result = simulate(IntegralLaw(ROBOT), Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.2))
    figures = _simulation_figures(result)
    (ax,) = figures["state"].axes
    assert ax.get_ylabel() == "state [rad·s]"
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == ["I1", "I2"]
    assert result.state is not None
    np.testing.assert_array_equal(lines[1].get_ydata(), result.state[:, 1])
    adaptive = simulate(Adaptive(ROBOT), Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.05))
    assert "state" not in _simulation_figures(adaptive)  # estimates have their own figures
