"""The reference ahead of now (controllers/preview.py, simulation/preview.py): a law that declares
``preview_times`` gets the trajectory's own samples at ``t + s_j``, the same for every run of a
batch; a law that declares none gets None; bad offsets are refused naming the law."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from twolink_pin import Plant, SimulationConfig, load_robot, simulate, simulate_batch
from twolink_pin.controllers import ComputedTorque, LawInput, ModelPredictive, MPCGains
from twolink_pin.errors import InvalidParameterError
from twolink_pin.simulation import law_input
from twolink_pin.trajectory import default_trajectory

ROBOT = load_robot()
OFFSETS = (0.0, 0.013, 0.05, 0.2)


class Looking(ComputedTorque, register=False):
    """Computed torque that keeps every preview it is handed (the law's inputs are read-only)."""

    name = "looking"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.seen: list[tuple[float, Any, int]] = []

    def preview_times(self) -> Any:
        return OFFSETS

    def compute(self, x: LawInput, terms: Any) -> Any:
        self.seen.append((x.t, x.preview, x.q.shape[0]))
        return super().compute(x, terms)


def test_the_preview_is_the_trajectorys_samples_at_the_times_asked_for_every_run() -> None:
    """A batch of three runs: at every evaluation the preview's times are ``t + s_j`` and its
    q, q̇, q̈ equal ``trajectory.sample`` there (a second call, outside the engine) — one row,
    the same for every run — and the arrays are read-only."""
    trajectory = default_trajectory(ROBOT)
    law = Looking(ROBOT)
    offsets = np.array([[0.1, -0.1], [0.0, 0.05], [-0.2, 0.0]])
    simulate_batch(law, Plant(ROBOT), trajectory, SimulationConfig(duration=0.02), q0_offsets=offsets)
    assert len(law.seen) >= 4 * 20  # every RK4 stage of every step
    for t, preview, runs in law.seen:
        assert runs == 3
        np.testing.assert_allclose(preview.t, t + np.array(OFFSETS), rtol=0, atol=1e-15)
        expected = trajectory.sample(preview.t)
        for got, want in ((preview.q, expected.q), (preview.v, expected.v), (preview.a, expected.a)):
            assert got.shape == (1, len(OFFSETS), ROBOT.nv)
            np.testing.assert_array_equal(got[0], want)
            assert not got.flags.writeable


def test_a_law_that_declares_no_preview_gets_none() -> None:
    seen = []

    class Plain(ComputedTorque, register=False):
        name = "plain"

        def compute(self, x: LawInput, terms: Any) -> Any:
            seen.append(x.preview)
            return super().compute(x, terms)

    simulate(Plain(ROBOT), Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.005))
    assert seen and all(p is None for p in seen)


def test_a_planning_law_gets_its_preview_where_it_plans() -> None:
    """mpc (replans every 10 ms) is handed the preview at its replans, in ``update`` and in the
    ``compute`` of that instant, and None between: its row times ``i h / S`` ahead."""
    law = ModelPredictive(ROBOT)
    seen: list[tuple[str, float, Any]] = []
    update, compute = law.update, law.compute

    def spy_update(x: LawInput, terms: Any) -> Any:
        seen.append(("update", x.t, x.preview))
        return update(x, terms)

    def spy_compute(x: LawInput, terms: Any) -> Any:
        seen.append(("compute", x.t, x.preview))
        return compute(x, terms)

    law.update, law.compute = spy_update, spy_compute  # type: ignore[method-assign]
    # no step check: its copy of the law would carry the spies (one more update at t = 0)
    simulate(law, Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.025, check_step=False))
    updates = [(t, p) for kind, t, p in seen if kind == "update"]
    assert [round(t, 9) for t, _ in updates] == [0.0, 0.01, 0.02]
    for t, preview in updates:
        np.testing.assert_allclose(preview.t, t + law.horizon.times, rtol=0, atol=1e-15)
    between = [p for kind, t, p in seen if kind == "compute" and round(t / 0.01, 9) % 1 != 0]
    assert between and all(p is None for p in between)


def test_law_input_samples_the_preview_from_the_trajectory() -> None:
    trajectory = default_trajectory(ROBOT)
    law = Looking(ROBOT)
    s = trajectory.sample(0.3)
    x = law_input(
        law, 0.3, s.q[None], s.v[None], np.zeros((1, 0)), s.q[None], s.v[None], s.a[None], trajectory
    )
    np.testing.assert_array_equal(x.preview.q[0], trajectory.sample(0.3 + np.array(OFFSETS)).q)
    assert (
        law_input(law, 0.3, s.q[None], s.v[None], np.zeros((1, 0)), s.q[None], s.v[None], s.a[None]).preview
        is None
    )


@pytest.mark.parametrize(
    ("offsets", "words"),
    [
        ([0.0, -0.1], r"preview_times\(\)\[1\] = -0.1 is invalid"),
        ([0.0, float("nan")], r"preview_times\(\)\[1\] = nan is invalid"),
        ([], r"a 1-D sequence of 1 to"),
        ([[0.1]], r"a 1-D sequence of 1 to"),
        ("soon", r"offsets \[s\] >= 0 from now"),
    ],
)
def test_bad_preview_times_are_refused_naming_the_law(offsets: Any, words: str) -> None:
    class Bad(ComputedTorque, register=False):
        name = "bad-preview"

        def preview_times(self) -> Any:
            return offsets

    with pytest.raises(InvalidParameterError, match=rf"law 'bad-preview': .*{words}"):
        simulate(Bad(ROBOT), Plant(ROBOT), default_trajectory(ROBOT), SimulationConfig(duration=0.005))


def test_extrapolate_asks_for_no_preview() -> None:
    assert ModelPredictive(ROBOT, MPCGains(reference_ahead="extrapolate")).preview_times() is None
    assert ModelPredictive(ROBOT).preview_times() is not None
