"""The rigid-body terms a law may ask for (``Terms.mass/gravity/bias/solve_mass/frame``).

Each against an independent computation:

* ``mass`` against columns of RNEA (``M e_k = rnea(q, 0, e_k) − rnea(q, 0, 0)``) and CRBA on
  the believed model; ``gravity`` against ``computeGeneralizedGravity`` and RNEA at rest;
  ``bias`` against ``nonLinearEffects`` and the model term ``M̂·0 + Ĉ(q, q̇) q̇ + ĝ``;
* ``solve_mass`` against ABA (``aba(q, 0, b + g) = M⁻¹ b``);
* the frame's Jacobian against central differences of its pose, ``J̇ q̇`` against central
  differences of ``J(q + t q̇) q̇``;
* a batch (one believed model per run) equals N single runs, bit for bit.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.controllers import PDFeedforward
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.model.parameters import model_with_parameters
from twolink_pin.simulation import terms_for

ROBOTS = ("twolink", "ur5", "panda")


@functools.cache
def robot(name: str) -> RobotModel:
    return load_robot(name)


class Probe(PDFeedforward, register=False):
    """A law used only to build terms (never run)."""


def _state(r: RobotModel, seed: int, n: int = 1) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5, 1.5, (n, r.nv)), rng.uniform(-2.0, 2.0, (n, r.nv))


@pytest.mark.parametrize("name", ROBOTS)
@pytest.mark.parametrize("scale", [None, 1.3])
def test_mass_gravity_bias_against_rnea_and_pinocchio(name: str, scale: float | None) -> None:
    r = robot(name)
    p = None if scale is None else scale * np.asarray(r.p)
    terms = terms_for(Probe(r, model_parameters=p))
    believed = r.model if p is None else model_with_parameters(r.model, r.parameter_map, p)
    data = believed.createData()
    zero = np.zeros(r.nv)
    for seed in range(3):
        q, v = _state(r, seed)
        M = terms.mass(q)
        assert M.shape == (1, r.nv, r.nv)
        rest = pin.rnea(believed, data, q[0], zero, zero).copy()
        columns = np.stack([pin.rnea(believed, data, q[0], zero, e) - rest for e in np.eye(r.nv)], axis=1)
        np.testing.assert_allclose(M[0], columns, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(M[0], M[0].T, rtol=0, atol=0)
        crba = pin.crba(believed, data, q[0])
        np.testing.assert_allclose(np.triu(M[0]), np.triu(crba), rtol=1e-12, atol=1e-12)
        g = terms.gravity(q)
        np.testing.assert_allclose(g[0], rest, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(
            g[0], pin.computeGeneralizedGravity(believed, data, q[0]), rtol=1e-12, atol=1e-12
        )
        b = terms.bias(q, v)
        np.testing.assert_allclose(b, terms.model(q, v, v, np.zeros_like(v)), rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(
            b[0], pin.nonLinearEffects(believed, data, q[0], v[0]), rtol=1e-12, atol=1e-12
        )
        # the model term is M a + C w + g: its a-part is M
        a = np.random.default_rng(seed + 10).normal(size=(1, r.nv))
        np.testing.assert_allclose(terms.model(q, v, v, a), b + np.matvec(M, a), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", ROBOTS)
def test_solve_mass_against_aba(name: str) -> None:
    r = robot(name)
    terms = terms_for(Probe(r))
    data = r.model.createData()
    zero = np.zeros(r.nv)
    q, _ = _state(r, 4)
    b = np.random.default_rng(5).normal(size=(1, r.nv))
    x = terms.solve_mass(q, b)
    g = pin.computeGeneralizedGravity(r.model, data, q[0]).copy()
    np.testing.assert_allclose(x[0], pin.aba(r.model, data, q[0], zero, b[0] + g), rtol=1e-9, atol=1e-9)
    B = np.random.default_rng(6).normal(size=(1, r.nv, 3))
    X = terms.solve_mass(q, B)
    np.testing.assert_allclose(np.matmul(terms.mass(q), X), B, rtol=1e-9, atol=1e-9)
    with pytest.raises(InvalidParameterError, match="b"):
        terms.solve_mass(q, np.zeros((1, r.nv + 1)))


def _pose(r: RobotModel, q: np.ndarray) -> pin.SE3:
    data = r.model.createData()
    pin.framesForwardKinematics(r.model, data, q)
    return data.oMf[r.ee_frame_id].copy()


def _check_frame(r: RobotModel, q: np.ndarray, v: np.ndarray) -> None:
    terms = terms_for(Probe(r))
    f = terms.frame(q[None], v[None])
    pose = _pose(r, q)
    np.testing.assert_allclose(f.position[0], pose.translation, atol=1e-12)
    np.testing.assert_allclose(f.rotation[0], pose.rotation, atol=1e-12)
    h = 1e-6
    J = np.empty((6, r.nv))
    for k in range(r.nv):
        e = np.zeros(r.nv)
        e[k] = h
        plus, minus = _pose(r, q + e), _pose(r, q - e)
        J[:3, k] = (plus.translation - minus.translation) / (2 * h)
        J[3:, k] = pin.log3(plus.rotation @ minus.rotation.T) / (2 * h)  # world-aligned ω
    np.testing.assert_allclose(f.jacobian[0], J, rtol=1e-6, atol=1e-7)
    # J̇ q̇ = d/dt [J(q + t q̇) q̇] at t = 0 (q̈ = 0)
    t = 1e-5
    plus = terms.frame((q + t * v)[None], v[None]).jacobian[0] @ v
    minus = terms.frame((q - t * v)[None], v[None]).jacobian[0] @ v
    np.testing.assert_allclose(f.drift[0], (plus - minus) / (2 * t), rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("name", ROBOTS)
def test_frame_against_finite_differences(name: str) -> None:
    r = robot(name)
    for seed in range(3):
        q, v = _state(r, 20 + seed)
        _check_frame(r, q[0], v[0])


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-3.0, 3.0), min_size=7, max_size=7),
    st.lists(st.floats(-3.0, 3.0), min_size=7, max_size=7),
)
def test_frame_any_state_of_the_panda(q: list[float], v: list[float]) -> None:
    _check_frame(robot("panda"), np.array(q), np.array(v))


def test_named_frame_and_unknown_frame() -> None:
    r = robot("ur5")
    terms = terms_for(Probe(r))
    q, v = _state(r, 7)
    other = r.model.frames[r.ee_frame_id - 2].name
    f = terms.frame(q, v, other)
    data = r.model.createData()
    pin.framesForwardKinematics(r.model, data, q[0])
    np.testing.assert_allclose(f.position[0], data.oMf[r.model.getFrameId(other)].translation, atol=1e-12)
    with pytest.raises(InvalidParameterError, match="no_such_frame"):
        terms.frame(q, v, "no_such_frame")


@pytest.mark.parametrize("name", ["twolink", "panda"])
def test_batch_equals_single_runs(name: str) -> None:
    r = robot(name)
    n = 4
    rows = np.asarray(r.p) * np.linspace(0.7, 1.3, n)[:, None]
    batch = terms_for(Probe(r, model_parameters=rows), runs=n, threads=1)
    q, v = _state(r, 30, n)
    b = np.random.default_rng(31).normal(size=(n, r.nv))
    got = (batch.mass(q), batch.gravity(q), batch.bias(q, v), batch.solve_mass(q, b), batch.frame(q, v))
    for i in range(n):
        single = terms_for(Probe(r, model_parameters=rows[i]))
        one = (
            single.mass(q[i : i + 1]),
            single.gravity(q[i : i + 1]),
            single.bias(q[i : i + 1], v[i : i + 1]),
            single.solve_mass(q[i : i + 1], b[i : i + 1]),
        )
        for a, c in zip(got[:4], one, strict=True):
            np.testing.assert_array_equal(a[i : i + 1], c)
        frame = single.frame(q[i : i + 1], v[i : i + 1])
        for a, c in zip(got[4], frame, strict=True):
            np.testing.assert_array_equal(a[i : i + 1], c)
    # one reference row against per-run models: every run's own model
    g = batch.gravity(q[:1])
    assert g.shape == (n, r.nv)
    assert batch.frame(q[:1], v[:1]).jacobian.shape == (1, 6, r.nv)


@pytest.mark.parametrize("runs", [1, 3])
def test_one_pass_per_state_gives_the_frame_mass_bias_and_gravity(
    runs: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Once a law has asked for a dynamics term, ``frame`` runs one Pinocchio pass per run that
    also gives ``M̂``, ``Ĉ q̇ + ĝ`` and ``ĝ`` at that state: asking for them then makes no other
    Pinocchio call, and they equal ``crba``, ``nonLinearEffects`` and
    ``computeGeneralizedGravity`` (to rounding: the pass works in the world frame)."""
    r = robot("panda")
    rows = np.asarray(r.p) * np.linspace(0.8, 1.2, runs)[:, None]
    terms = terms_for(Probe(r, model_parameters=rows if runs > 1 else rows[0]), runs=runs, threads=1)
    q0, _ = _state(r, 40, runs)
    terms.mass(q0)  # the law has asked for a dynamics term
    q, v = _state(r, 41, runs)
    frame = terms.frame(q, v)
    expected = []
    for i in range(runs):
        model = model_with_parameters(r.model, r.parameter_map, rows[i])
        data = model.createData()
        upper = pin.crba(model, data, q[i])
        expected.append(
            (
                np.triu(upper) + np.triu(upper, 1).T,
                pin.nonLinearEffects(model, data, q[i], v[i]).copy(),
                pin.computeGeneralizedGravity(model, data, q[i]).copy(),
            )
        )

    def no_second_call(*args: object) -> None:
        raise AssertionError("a second Pinocchio call for a term the frame's pass gave")

    for name in ("crba", "nonLinearEffects", "computeGeneralizedGravity", "computeAllTerms"):
        monkeypatch.setattr(pin, name, no_second_call)
    M, bias, gravity = terms.mass(q), terms.bias(q, v), terms.gravity(q)
    for i, (M_i, bias_i, gravity_i) in enumerate(expected):
        np.testing.assert_allclose(M[i], M_i, rtol=0, atol=1e-12)
        np.testing.assert_allclose(bias[i], bias_i, rtol=0, atol=1e-11)
        np.testing.assert_allclose(gravity[i], gravity_i, rtol=0, atol=1e-11)
    assert frame.jacobian.shape == (runs, 6, r.nv)
    monkeypatch.undo()
    alone = terms_for(Probe(r, model_parameters=rows[0]))  # the kinematics alone: the same frame, bit for bit
    for a, b in zip(alone.frame(q[:1], v[:1]), frame, strict=True):
        np.testing.assert_array_equal(a, b[:1])
