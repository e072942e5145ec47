"""Every array a law gets from ``Terms`` is read-only, and a law that writes into one is an
error naming the law (issue 23: a law must not change what later evaluations see, e.g. the
cached mass matrix that the next ``terms.mass`` call returns)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from conftest_sim import ROBOT, TRAJECTORY

from twolink_pin.controllers import Controller, LawInput, LawOutput, Terms
from twolink_pin.controllers.gains import Gains
from twolink_pin.errors import ControllerError
from twolink_pin.plant import Plant
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, simulate, terms_for

OUTPUTS: dict[str, Callable[[Terms, np.ndarray, np.ndarray], list[np.ndarray]]] = {
    "model": lambda t, q, v: [t.model(q, v, v, v)],
    "regressor": lambda t, q, v: [t.regressor(q, v, v, v)],
    "friction_regressor": lambda t, q, v: [t.friction_regressor(v)],
    "mass": lambda t, q, v: [t.mass(q)],
    "gravity": lambda t, q, v: [t.gravity(q)],
    "bias": lambda t, q, v: [t.bias(q, v)],
    "solve_mass": lambda t, q, v: [t.solve_mass(q, v), t.solve_mass(q, np.stack([v, v], axis=2))],
    "frame": lambda t, q, v: list(t.frame(q, v)),
}


@pytest.mark.parametrize("runs", [1, 3])
@pytest.mark.parametrize("what", sorted(OUTPUTS))
def test_every_terms_output_is_read_only(what: str, runs: int) -> None:
    law = make_scenario("pd", ROBOT).controller
    terms = terms_for(law, runs, threads=1)
    rng = np.random.default_rng(1)
    q, v = rng.uniform(-1, 1, (runs, ROBOT.nv)), rng.uniform(-1, 1, (runs, ROBOT.nv))
    for array in OUTPUTS[what](terms, q, v):
        assert array.shape[0] == runs
        before = array.copy()
        with pytest.raises(ValueError, match="read-only"):
            array[...] = 0.0
        np.testing.assert_array_equal(array, before)


class WritesGravity(Controller, register=False):
    """Writes into the gravity vector Terms gave it."""

    name = "test-writes-gravity"
    title = "writes gravity"
    Gains = Gains
    what = "gravity"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if self.what == "gravity":
            g = terms.gravity(x.q)
            g *= 2.0
        elif self.what == "mass":
            terms.mass(x.q)[:, 0, 0] = 1.0
        else:
            terms.frame(x.q, x.v).jacobian[:] = 0.0
        return LawOutput(-100.0 * (x.q - x.q_des) - 20.0 * (x.v - x.v_des))


@pytest.mark.parametrize("what", ["gravity", "mass", "jacobian"])
def test_a_law_writing_into_a_terms_output_is_an_error_naming_the_law(what: str) -> None:
    law = WritesGravity(ROBOT)
    law.what = what
    with pytest.raises(ControllerError) as caught:
        simulate(law, Plant(ROBOT), TRAJECTORY, SimulationConfig(duration=0.01))
    message = str(caught.value)
    assert "test-writes-gravity" in message and "read-only" in message and "Terms" in message
    assert caught.value.time == 0.0
