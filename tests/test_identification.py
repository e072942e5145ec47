"""Parameter identification: exact on noise-free data, honest standard deviations on noisy data,
refusals that say what is wrong and where, excitations that do what they claim, and the loop
closed (identify, then control with what was identified).

Independent checks: the observation matrix against RNEA plus friction, condition numbers and
Gram eigenvalues against numpy on matrices built here from Pinocchio's regressor, the averaged
adaptation rates against the Gram formula written out, the twolink's β → p conversion against
the closed form p1 = β1 + β4, p2 = β4, p3 = l1 β2, Fourier derivatives against finite differences.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin import InvalidParameterError, RunSpec, load_robot, make_scenario, simulate
from twolink_pin.cli import main
from twolink_pin.errors import InputFileError
from twolink_pin.identification import (
    ExcitationDesign,
    IdentificationOptions,
    IdentifiedParameters,
    ParameterSet,
    RunLog,
    add_noise,
    averaged_adaptation,
    excitation_measures,
    identify,
    map_parameters,
    optimise_excitation,
    read_log,
    read_parameter_file,
    simulate_log,
    write_log,
)
from twolink_pin.identification.excitation import ExcitationLimits
from twolink_pin.identification.simulated import plant_friction
from twolink_pin.identification.weighted_solve import solve
from twolink_pin.simulation import SimulationConfig
from twolink_pin.trajectory import FourierTrajectory, default_trajectory, read_trajectory_file
from twolink_pin.trajectory.file import write_trajectory_file
from twolink_pin.twolink import excitation as twolink_excitation

FIXTURES = Path(__file__).parent / "fixtures"
NOISE_Q, NOISE_TAU = 1e-4, 0.05
"""The Monte Carlo's noise: ten times encoder-level positions [rad], about 1 % of the torques [N·m]."""


@pytest.fixture(scope="module")
def twolink():
    return load_robot("twolink")


@pytest.fixture(scope="module")
def twolink_log(twolink):
    """A noise-free closed-loop log along the twolink's stored excitation: 20 s at 2 kHz."""
    return simulate_log(twolink, twolink_excitation.identification_excitation(), duration=20.0)


@pytest.fixture(scope="module")
def twolink_log_1khz(twolink):
    """A noise-free closed-loop log along the stored excitation: 20 s at 1 kHz (the noise tests')."""
    return simulate_log(twolink, twolink_excitation.identification_excitation(), duration=20.0, dt=1e-3)


def _relative_errors(estimate: np.ndarray, true: np.ndarray) -> np.ndarray:
    """|θ̂ − θ| / |θ|, and |θ̂| for parameters whose true value is 0 (in the unit of the others)."""
    return np.abs(estimate - true) / np.where(np.abs(true) > 0, np.abs(true), 1.0)


# ------------------------------------------------------------------ Fourier trajectories


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 6), st.floats(2.0, 20.0))
def test_fourier_derivatives_periodicity_mean_and_bounds(seed: int, harmonics: int, period: float) -> None:
    """q̇, q̈ and jerk are the derivatives of q (central differences, 1e-6 relative), the motion
    repeats after one period, its mean over a period is the offset, and the closed-form bounds
    are never exceeded."""
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(2, 3, harmonics))
    trajectory = FourierTrajectory(period, a, b, rng.normal(size=3))
    t = np.linspace(0.0, period, 4001)
    h = 1e-5
    s, plus, minus = trajectory.sample(t), trajectory.sample(t + h), trajectory.sample(t - h)
    for up, down, derivative in ((plus.q, minus.q, s.v), (plus.v, minus.v, s.a), (plus.a, minus.a, s.jerk)):
        scale = max(1.0, float(np.abs(derivative).max()))
        np.testing.assert_allclose((up - down) / (2 * h), derivative, rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose(trajectory.sample(t + period).q, s.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(s.q[:-1].mean(axis=0), trajectory.offset, rtol=0, atol=1e-9)
    q_bound, v_bound, a_bound = trajectory.bounds
    assert np.all(np.abs(s.q - trajectory.offset).max(axis=0) <= q_bound + 1e-12)
    assert np.all(np.abs(s.v).max(axis=0) <= v_bound + 1e-12)
    assert np.all(np.abs(s.a).max(axis=0) <= a_bound + 1e-12)


def test_fourier_refuses_mismatched_coefficients() -> None:
    with pytest.raises(
        InvalidParameterError,
        match=r"b = 'shape \(2, 4\)' is invalid: expected cosine coefficients \[rad/s\] like a, shape \(2, 3\)",
    ):
        FourierTrajectory(10.0, np.ones((2, 3)), np.ones((2, 4)), [0.0, 0.0])
    with pytest.raises(InvalidParameterError, match="period = 0"):
        FourierTrajectory(0, np.ones((2, 3)), np.ones((2, 3)), [0.0, 0.0])


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_fourier_trajectory_file_round_trip(tmp_path: Path, twolink, suffix: str) -> None:
    """excite's file format reads back as the same trajectory (JSON and TOML)."""
    original = twolink_excitation.identification_excitation()
    path = write_trajectory_file(tmp_path / f"ex{suffix}", original)
    back = read_trajectory_file(path, twolink)
    assert isinstance(back, FourierTrajectory)
    t = np.linspace(0.0, 10.0, 101)
    np.testing.assert_array_equal(back.sample(t).q, original.sample(t).q)


def test_via_point_trajectory_toml_round_trip(tmp_path: Path, twolink) -> None:
    original = default_trajectory(twolink)
    back = read_trajectory_file(write_trajectory_file(tmp_path / "via.toml", original), twolink)
    np.testing.assert_array_equal(back.via_q, original.via_q)
    assert back.period == original.period


def test_fourier_file_errors_name_the_key(tmp_path: Path, twolink) -> None:
    def write(document: dict) -> Path:
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(document))
        return path

    good = twolink_excitation.identification_excitation().as_dict()
    with pytest.raises(InvalidParameterError, match=r"fourier.a = 'shape \(1, 5\)'.* 2 rows"):
        read_trajectory_file(write({"fourier": good | {"a": good["a"][:1]}}), twolink)
    with pytest.raises(InvalidParameterError, match=r"fourier.harmonics = 4 .* coefficients per row"):
        read_trajectory_file(write({"fourier": good | {"harmonics": 4}}), twolink)
    with pytest.raises(InvalidParameterError, match=r"times = .* no other key beside a 'fourier' table"):
        read_trajectory_file(write({"fourier": good, "times": [0, 1]}), twolink)
    with pytest.raises(InvalidParameterError, match=r"q1.* within joint 1's limits .* over the period"):
        read_trajectory_file(write({"fourier": good | {"offset": [3.0, 0.0]}}), twolink)


# ------------------------------------------------------------------ logs and their errors


def _csv(path: Path, rows: list[list[object]], header: str = "t,q1,q2,tau1,tau2") -> Path:
    path.write_text(header + "\n" + "\n".join(",".join(str(x) for x in row) for row in rows) + "\n")
    return path


def _rows(n: int) -> list[list[object]]:
    return [[0.001 * k, 0.1 * k, 0.2, 1.0, 2.0] for k in range(n)]


def test_csv_missing_column_names_it_and_the_header_line(tmp_path: Path) -> None:
    path = _csv(tmp_path / "log.csv", [[0, 0, 0, 0]] * 20, header="t,q1,q2,tau1")
    with pytest.raises(InputFileError) as err:
        read_log(path, 2)
    assert str(err.value) == (
        f"{path}: line 1: missing column 'tau2' (expected t, q1, q2, tau1, tau2 for nv = 2, optionally "
        "v1..v2; found 't', 'q1', 'q2', 'tau1')"
    )


def test_csv_nan_names_row_line_and_column(tmp_path: Path) -> None:
    rows = _rows(20)
    rows[6][2] = "nan"
    path = _csv(tmp_path / "log.csv", rows)
    with pytest.raises(InputFileError) as err:
        read_log(path, 2)
    assert str(err.value) == f"{path}: data row 7 (line 8), column 'q2': nan is not a finite number"


def test_csv_text_cell_and_short_row(tmp_path: Path) -> None:
    rows = _rows(20)
    rows[3][4] = "1,5"  # a decimal comma: one field too many
    path = _csv(tmp_path / "log.csv", rows)
    with pytest.raises(InputFileError, match=r"data row 4 \(line 5\): 6 fields where the header has 5"):
        read_log(path, 2)
    rows = _rows(20)
    rows[2][1] = "abc"
    with pytest.raises(InputFileError, match=r"data row 3 \(line 4\), column 'q1': 'abc' is not a number"):
        read_log(_csv(tmp_path / "log2.csv", rows), 2)


def test_csv_non_monotonic_time_names_the_row(tmp_path: Path) -> None:
    rows = _rows(20)
    rows[5][0] = 0.003
    path = _csv(tmp_path / "log.csv", rows)
    with pytest.raises(InputFileError) as err:
        read_log(path, 2)
    assert str(err.value) == (
        f"{path}: data row 6 (line 7), column 't': t = 0.003 s is not after the previous row's 0.004 s "
        "(time must increase strictly)"
    )


def test_too_few_samples_for_the_parameters_is_refused(tmp_path: Path) -> None:
    """The UR5 has 36 base parameters and 12 friction coefficients: 30 samples are too few."""
    ur5 = load_robot("ur5")
    rows = [[0.001 * k, *([0.1 * k] * 6), *([1.0] * 6)] for k in range(30)]
    header = "t," + ",".join(f"q{j}" for j in range(1, 7)) + "," + ",".join(f"tau{j}" for j in range(1, 7))
    path = _csv(tmp_path / "log.csv", rows, header)
    log = read_log(path, 6)
    with pytest.raises(InputFileError) as err:
        identify(log, ur5)
    assert str(err.value) == (
        f"{path}: has 30 samples; identifying 48 parameters needs at least 48 (more samples, or fewer parameters)"
    )


def test_npz_errors_and_round_trips(tmp_path: Path, twolink_log: RunLog) -> None:
    path = tmp_path / "log.npz"
    np.savez(path, t=np.arange(20.0), q=np.zeros((20, 2)))
    with pytest.raises(
        InputFileError, match=r"missing array 'tau' \(expected t \(K,\), q \(K, 2\), tau \(K, 2\)"
    ):
        read_log(path, 2)
    q = np.zeros((20, 2))
    q[4, 1] = np.inf
    np.savez(path, t=np.arange(20.0), q=q, tau=np.zeros((20, 2)))
    with pytest.raises(InputFileError, match=r"sample 4 \(index into t\), column 'q\[:, 1\] \(q2\)': inf"):
        read_log(path, 2)
    for suffix in (".npz", ".csv"):
        short = RunLog(twolink_log.t[:200], twolink_log.q[:200], twolink_log.tau[:200], twolink_log.v[:200])
        back = read_log(write_log(tmp_path / f"log{suffix}", short), 2)
        np.testing.assert_array_equal(back.q, short.q)
        np.testing.assert_array_equal(back.tau, short.tau)
        np.testing.assert_array_equal(back.v, short.v)


# ----------------------------------------------------------- the model and the estimator


@pytest.mark.parametrize("name", ["twolink", "ur5"])
def test_observation_times_true_parameters_is_rnea_plus_friction(name: str) -> None:
    robot = load_robot(name)
    pset = ParameterSet.of(robot)
    friction = plant_friction(robot)
    theta = pset.true_values(robot.model, friction)
    rng = np.random.default_rng(1)
    q, v, a = rng.uniform(-1, 1, (3, 20, robot.nv))
    W = pset.observation(robot.model, q, v, a)
    data = robot.create_data()
    expected = np.array([pin.rnea(robot.model, data, *s) for s in zip(q, v, a)]) + friction.torque(v)
    np.testing.assert_allclose(W @ theta, expected, rtol=0, atol=1e-10)


def test_weighted_least_squares_standard_deviations_are_honest() -> None:
    """Independent rows, joint 2 ten times noisier: the weights recover each joint's σ to 10 %,
    and over 300 draws the estimates' scatter matches the stated σ to 15 % and the true
    values fall within ±3σ in more than 98 % of cases."""
    rng = np.random.default_rng(3)
    W = rng.normal(size=(400, 2, 5))
    theta = rng.normal(size=5)
    sigma = np.array([0.01, 0.1])
    z, stated = [], []
    for _ in range(300):
        y = W @ theta + sigma * rng.standard_normal((400, 2))
        estimate, covariance, weights = solve(W, y)
        np.testing.assert_allclose(weights, sigma, rtol=0.1)
        z.append((estimate - theta) / np.sqrt(np.diag(covariance)))
        stated.append(np.sqrt(np.diag(covariance)))
    z = np.array(z)
    np.testing.assert_allclose(z.std(axis=0), 1.0, rtol=0.15)
    assert np.mean(np.abs(z) <= 3) > 0.98


def test_noise_free_twolink_recovered_to_1e6(twolink, twolink_log: RunLog) -> None:
    """Base parameters and friction from a closed-loop log: 1e-6 relative (measured 5e-9); the
    validation period predicts the torque to 1e-6 N·m."""
    result = identify(twolink_log, twolink)
    assert result.names[:4] == ("link1.Izz + 0.1444 link2.m", "link2.mcx", "link2.mcy", "link2.Izz")
    assert _relative_errors(result.estimate, result.true).max() < 1e-6
    assert result.validation is not None and result.validation.rms.max() < 1e-6
    assert result.condition_number < 5


def test_noise_free_ur5_recovered_to_1e6() -> None:
    """The UR5's 36 base parameters and 12 friction coefficients from 10 s (one period; measured
    3.7e-7) along an excitation written by ``twolink-pin excite --robot ur5``
    (tests/fixtures/ur5_excitation.json)."""
    ur5 = load_robot("ur5")
    trajectory = read_trajectory_file(FIXTURES / "ur5_excitation.json", ur5)
    log = simulate_log(ur5, trajectory, duration=10.0)
    result = identify(log, ur5, IdentificationOptions(validation=0.0))
    assert result.size == 48
    assert _relative_errors(result.estimate, result.true).max() < 1e-6


@pytest.mark.slow
def test_stated_sigma_is_honest_over_50_noise_seeds(twolink, twolink_log_1khz: RunLog) -> None:
    """50 seeds of σ_q = 1e-4 rad, σ_τ = 0.05 N·m on a 20-s log, instrumental variables (the
    default when the reference is known): every parameter's true value is within ±3σ in at
    least 90 % of the seeds, 97 % over all (a Gaussian gives 99.7 %), and the normalised errors
    scatter like N(0, 1) within a factor 1.5 (measured: 99.0 %, 0.78–1.19)."""
    log = twolink_log_1khz
    options = IdentificationOptions(validation=0.0)
    z = np.array(
        [
            (r.estimate - r.true) / r.std
            for r in (
                identify(add_noise(log, NOISE_Q, NOISE_TAU, seed), twolink, options) for seed in range(50)
            )
        ]
    )
    inside = np.abs(z) <= 3
    assert inside.mean(axis=0).min() >= 0.9
    assert inside.mean() >= 0.97
    assert np.all((z.std(axis=0) > 1 / 1.5) & (z.std(axis=0) < 1.5))


def test_least_squares_is_biased_by_position_noise_and_instruments_are_not(
    twolink, twolink_log_1khz: RunLog
) -> None:
    """σ_q = 1e-4 rad, 10 seeds: least squares underestimates link2.Izz by ~8 % (errors in
    variables, 6 times its stated σ); instrumental variables are within 1 %."""
    log = twolink_log_1khz
    ls, iv = [], []
    for seed in range(10):
        noisy = add_noise(log, 1e-4, 0.05, seed)
        ls.append(identify(noisy, twolink, IdentificationOptions(validation=0.0, instruments=False)))
        iv.append(identify(noisy, twolink, IdentificationOptions(validation=0.0)))
    assert {r.method for r in ls} == {"least squares"} and {r.method for r in iv} == {
        "instrumental variables"
    }
    izz = 3
    bias_ls = np.mean([r.estimate[izz] for r in ls]) / 0.4 - 1
    bias_iv = np.mean([r.estimate[izz] for r in iv]) / 0.4 - 1
    assert bias_ls < -0.05 and abs(bias_ls) > 5 * np.mean([r.std[izz] for r in ls]) / 0.4
    assert abs(bias_iv) < 0.01


def test_noise_makes_the_estimates_degrade(twolink, twolink_log: RunLog) -> None:
    """Ten times the torque noise: ten times the standard deviations (to 30 %)."""
    small = identify(add_noise(twolink_log, 0.0, 0.01, 1), twolink)
    large = identify(add_noise(twolink_log, 0.0, 0.1, 1), twolink)
    np.testing.assert_allclose(large.std / small.std, 10.0, rtol=0.3)


# ------------------------------------------------------------------ excitation measures


def test_condition_number_and_gram_against_an_independent_computation(twolink) -> None:
    trajectory = default_trajectory(twolink)
    measures = excitation_measures(twolink, trajectory, samples=500)
    P = ParameterSet.of(twolink).base.matrix
    data = twolink.create_data()
    t = trajectory.period * np.arange(500) / 500
    ref = trajectory.sample(t)
    rows = [
        np.hstack(
            [
                pin.computeJointTorqueRegressor(twolink.model, data, q, v, a) @ P,
                np.diag(v),
                np.diag(np.sign(v)),
            ]
        )
        for q, v, a in zip(ref.q, ref.v, ref.a)
    ]
    W = np.vstack(rows)
    assert measures.condition_number == pytest.approx(np.linalg.cond(W), rel=1e-10)
    gram = W.T @ W / 500
    assert measures.gram_min_eigenvalue_per_s == pytest.approx(np.linalg.eigvalsh(gram)[0], rel=1e-8)
    assert measures.gram_min_eigenvalue == pytest.approx(np.linalg.eigvalsh(gram)[0] * 4.0, rel=1e-8)


def test_averaged_adaptation_matches_the_gram_formula(twolink) -> None:
    """Rates = eig(Γ (1/T) Σ Yᵀ K⁻¹ Y) with the report's K = 120, γ = (0.5, 0.15, 0.6)."""
    controller = make_scenario("adaptive", twolink).controller
    trajectory = default_trajectory(twolink)
    averaged = averaged_adaptation(controller, trajectory, samples=400)
    P = twolink.parameter_map.matrix
    data = twolink.create_data()
    ref = trajectory.sample(trajectory.period * np.arange(400) / 400)
    G = (
        sum(
            (Y := pin.computeJointTorqueRegressor(twolink.model, data, q, v, a) @ P).T @ Y / 120.0
            for q, v, a in zip(ref.q, ref.v, ref.a)
        )
        / 400
    )
    rates = np.sort(np.linalg.eigvals(np.diag(1 / np.array([0.5, 0.15, 0.6])) @ G).real)
    np.testing.assert_allclose(averaged.rates, rates, rtol=1e-10)
    assert averaged.slowest_time_constant == pytest.approx(1 / rates[0])
    assert averaged.slowest_time_constant > 100  # the report's trajectory: minutes


def test_the_predicted_error_on_a_grid_is_the_eigen_solution_of_the_averaged_system(twolink) -> None:
    """p̃(t) = V exp(−Λ t) V⁻¹ p̃(0) (Γ G diagonalised; a second method), on the evenly spaced
    grid a figure uses (stepped) and at scattered times (one expm each)."""
    controller = make_scenario("adaptive", twolink).controller
    averaged = averaged_adaptation(controller, default_trajectory(twolink), samples=400)
    rates, vectors = np.linalg.eig(averaged.rate_matrix)
    initial = np.array([0.3, -0.2, 0.1])
    for t in (np.linspace(0.0, 600.0, 301), np.array([7.0, 0.5, 250.0]), np.linspace(2.0, 3.0, 2)):
        expected = (vectors @ (np.exp(-np.outer(t, rates)) * np.linalg.solve(vectors, initial)).T).T.real
        np.testing.assert_allclose(averaged.predicted_error(initial, t), expected, rtol=1e-9, atol=1e-13)


def test_friction_puts_a_floor_under_the_condition_number(twolink) -> None:
    """Joint j's viscous and Coulomb columns (q̇_j, sgn q̇_j on the same rows) have cosine
    c_j = mean|q̇_j| / rms(q̇_j); by interlacing cond(W) ≥ √((1+c)/(1−c)) for any column
    scaling. Checked on a random matrix (the bound holds, column scaling cannot beat it) and
    on the three references; the optimised excitation is within 5 % of its floor, and the
    10× target (cond ≤ 1.135) would need c ≤ 0.126."""
    rng = np.random.default_rng(1)
    v = rng.normal(size=400)
    W = np.column_stack([v, np.sign(v), rng.normal(size=(400, 3))])
    c = np.abs(v).mean() / np.sqrt((v**2).mean())
    floor = np.sqrt((1 + c) / (1 - c))
    for scale in ([1, 1, 1, 1, 1], [3.0, 0.2, 1, 5, 0.1], [0.01, 10, 1, 1, 1]):
        assert np.linalg.cond(W * np.array(scale)) >= floor * (1 - 1e-12)
    for key, trajectory in twolink_excitation.trajectories(twolink).items():
        t = np.linspace(0.0, trajectory.period, 20001)[:-1]
        speed = trajectory.sample(t).v
        c = np.abs(speed).mean(axis=0) / np.sqrt((speed**2).mean(axis=0))
        floor = float(np.max(np.sqrt((1 + c) / (1 - c))))
        cond = excitation_measures(twolink, trajectory).condition_number
        assert cond >= floor * (1 - 1e-3), key
        if key == "identification":
            assert cond <= 1.05 * floor and floor == pytest.approx(2.318, abs=0.005)
    assert np.sqrt((1 + 0.126) / (1 - 0.126)) == pytest.approx(1.135, abs=0.001)


def test_stored_excitations_against_the_reports_trajectory(twolink) -> None:
    """The numbers docs/identification.md states: cond(W) 11.35 (report) against 2.39 (4.8× lower,
    not the 10× hoped for: the report's trajectory is already well conditioned), λ_min per second
    6× higher; the adaptation excitation's slowest time constant 1.2 s against 171 s."""
    rows = {row["trajectory"]: row for row in twolink_excitation.excitation_table(twolink)}
    assert rows["report"]["condition_number"] == pytest.approx(11.35, abs=0.01)
    assert rows["identification"]["condition_number"] == pytest.approx(2.386, abs=0.01)
    assert rows["report"]["condition_number"] / rows["identification"]["condition_number"] > 4.5
    assert (
        rows["identification"]["gram_min_eigenvalue_per_s"] > 5 * rows["report"]["gram_min_eigenvalue_per_s"]
    )
    assert rows["report"]["slowest_time_constant_s"] == pytest.approx(171.1, abs=0.5)
    assert rows["adaptation"]["slowest_time_constant_s"] == pytest.approx(1.2, abs=0.01)


def test_the_report_adaptive_law_converges_along_the_adaptation_excitation(twolink) -> None:
    """Within 5 % of p from t ≈ 6.5 s and to 1e-7 at 30 s; along the report's trajectory it is
    still 40–90 % off at 30 s (Fig. 27)."""
    runs = twolink_excitation.adaptive_runs(twolink, 30.0, keys=("report", "adaptation"))
    p = twolink.p
    fast, slow = runs["adaptation"], runs["report"]
    within = twolink_excitation.time_within(fast.t, fast.p_hat, p)
    assert within is not None and within < 10.0
    assert np.max(np.abs(fast.p_hat[-1] - p) / p) < 1e-7
    assert twolink_excitation.time_within(slow.t, slow.p_hat, p) is None
    assert np.min(np.abs(slow.p_hat[-1] - p) / p) > 0.3


def test_a_short_optimisation_meets_its_limits_and_improves(twolink) -> None:
    """One start, 15 iterations: sampled q, q̇, q̈ and τ within the limits, and a condition
    number below the start's."""
    design = ExcitationDesign(starts=1, max_iterations=15, seed=4)
    excitation = optimise_excitation(twolink, design)
    limits = ExcitationLimits().resolve(twolink)
    peaks = excitation.peaks
    tol = 1e-6
    assert np.all(np.array(peaks["q_min"]) >= limits["lower"] - tol)
    assert np.all(np.array(peaks["q_max"]) <= limits["upper"] + tol)
    assert np.all(np.array(peaks["v_max"]) <= limits["velocity"] + tol)
    assert np.all(np.array(peaks["a_max"]) <= limits["acceleration"] + tol)
    assert np.all(np.array(peaks["tau_max"]) <= limits["torque"] + tol)
    start = ExcitationDesign(starts=1, max_iterations=1, seed=4)
    assert (
        excitation.measures.condition_number < optimise_excitation(twolink, start).measures.condition_number
    )
    assert excitation.iterations == 15 and excitation.seconds > 0


@pytest.mark.slow
def test_the_default_design_reaches_the_floor_friction_puts_under_the_condition_number(twolink) -> None:
    """Re-optimising with the defaults (3 seeded starts, SLSQP) lands within 15 % of the floor
    √((1+c)/(1−c)) of its own excitation (proved in the test above: no column scaling beats
    it) and at least 4× better conditioned than the report's trajectory (docs/identification.md:
    4.8×). Not against the stored optimum: SLSQP's local optimum moves with the machine's
    floating-point kernels (2.3742 on one 2-core VM, 2.3859 stored, 2.5228 on another; this
    one's floor 2.342), so a test of the stored digits fails on a machine that is not ours."""
    fresh = optimise_excitation(twolink)
    trajectory = fresh.trajectory
    t = np.linspace(0.0, trajectory.period, 20001)[:-1]
    speed = trajectory.sample(t).v
    c = np.abs(speed).mean(axis=0) / np.sqrt((speed**2).mean(axis=0))
    floor = float(np.max(np.sqrt((1 + c) / (1 - c))))
    cond = fresh.measures.condition_number
    assert floor * (1 - 1e-3) <= cond <= 1.15 * floor
    report = excitation_measures(twolink, twolink_excitation.trajectories(twolink)["report"])
    assert cond < report.condition_number / 4


# ------------------------------------------------------------------ closing the loop


def test_twolink_base_parameters_map_to_the_reports_p(twolink) -> None:
    """p1 = β1 + β4, p2 = β4, p3 = l1 β2, for made-up β (mcy = 0)."""
    beta = np.array([2.5, 0.7, 0.0, 0.35])
    p = map_parameters(twolink, IdentifiedParameters("x", beta, np.full(4, 1e-3), None))
    np.testing.assert_allclose(p, [2.85, 0.35, 0.38 * 0.7], rtol=1e-12)


def test_a_significant_parameter_outside_the_map_is_refused(twolink) -> None:
    beta = np.array([2.5, 0.7, 0.05, 0.35])
    with pytest.raises(InvalidParameterError) as err:
        map_parameters(twolink, IdentifiedParameters("p.json", beta, np.full(4, 1e-3), None))
    assert err.value.name == "p.json: link2.mcy"
    assert "50.0 σ from 0" in str(err.value) and "(p1, p2, p3)" in str(err.value)


def test_a_file_without_sigma_drops_a_part_outside_the_map_by_its_torques_alone(twolink) -> None:
    """A URDF (or a null std) gives no σ: no division by it; mcy is dropped while its torques
    are within 1 % of the model's (a noisy fit's 0.025 % passes) and refused beyond, naming
    the file, the parameter and the share of the torques."""
    from twolink_pin.identification.parameters_file import UNKNOWN_SIGMA_TOLERANCE

    unknown = np.full(4, np.nan)
    small = np.array([2.5, 0.7, -0.000893693, 0.35])
    p = map_parameters(twolink, IdentifiedParameters("id.urdf", small, unknown, None))
    np.testing.assert_allclose(p, [2.85, 0.35, 0.38 * 0.7], rtol=1e-12)  # mcy, noise, left out
    large = np.array([2.5, 0.7, 0.05, 0.35])
    with pytest.raises(InvalidParameterError) as err:
        map_parameters(twolink, IdentifiedParameters("id.urdf", large, unknown, None))
    assert err.value.name == "id.urdf: link2.mcy" and "σ from" not in str(err.value)
    assert f"at most {100 * UNKNOWN_SIGMA_TOLERANCE:g} %" in str(err.value) and "no σ" in str(err.value)


def test_a_urdf_written_from_a_noisy_fit_is_believed_as_its_json_is(tmp_path: Path) -> None:
    """identify --noise-q 1e-4 --noise-tau 0.5 --write-urdf, then --model id.urdf: the law
    believes the same p as from the fit's own JSON (to the URDF's printed digits), and the run
    goes (it was refused: 'link2.mcy … 8.9e+299 σ from 0', a URDF's σ taken as 1e-300)."""
    from twolink_pin.identification import urdf_parameters

    urdf, saved = tmp_path / "id.urdf", tmp_path / "id.json"
    noisy = ["--noise-q", "1e-4", "--noise-tau", "0.5", "--duration", "12"]
    assert main(["identify", *noisy, "--write-urdf", str(urdf), "--save", str(saved)]) == 0
    robot = load_robot()
    from_urdf = map_parameters(robot, urdf_parameters(urdf, robot))
    from_json = map_parameters(robot, read_parameter_file(saved, robot))
    np.testing.assert_allclose(from_urdf, from_json, rtol=1e-8)
    assert main(["simulate", "computed-torque", "--model", str(urdf), "--duration", "0.2"]) == 0
    assert (
        main(
            [
                "compare",
                "computed-torque",
                f"computed-torque@model={urdf}",
                "--duration",
                "0.2",
                "--no-plot",
                "--out",
                str(tmp_path / "c"),
            ]
        )
        == 0
    )


def test_identify_then_control_with_what_was_identified(tmp_path: Path, twolink, twolink_log: RunLog) -> None:
    """identify --save writes the file; --p0 starts the adaptive-friction law at the identified
    values exactly (p mapped, friction), --model gives them to computed torque, and --p0 on a law
    that estimates nothing is refused."""
    from twolink_pin.files import write_json
    from twolink_pin.identification import identification_document

    found = identify(add_noise(twolink_log, NOISE_Q, NOISE_TAU, 0), twolink)
    path = write_json(tmp_path / "p.json", identification_document(found, twolink))
    identified = read_parameter_file(path, twolink)
    b = found.estimate

    def seeded(law: str, use: str):
        return RunSpec(law=law, parameters=str(path), parameters_use=use).build(twolink, identified)

    controller, plant = seeded("adaptive-friction", "p0")
    np.testing.assert_allclose(
        controller.initial_state(), [b[0] + b[3], b[3], 0.38 * b[1], *b[4:]], rtol=1e-12
    )
    assert plant.friction.parameters.tolist() == [0.4, 0.2, 0.2, 0.1]  # the plant is the true arm
    model, _ = seeded("computed-torque", "model")
    np.testing.assert_allclose(model.believed_parameters(), [b[0] + b[3], b[3], 0.38 * b[1]], rtol=1e-12)
    result = simulate(controller, plant, default_trajectory(twolink), SimulationConfig(duration=0.2))
    np.testing.assert_allclose(result.p_hat[0], controller.initial_state(), rtol=0, atol=0)
    with pytest.raises(
        InvalidParameterError, match="'computed-torque' estimates none: give its model with --model"
    ):
        seeded("computed-torque", "p0")


def test_a_parameter_file_of_another_robot_is_refused(tmp_path: Path, twolink) -> None:
    path = tmp_path / "p.json"
    path.write_text(json.dumps({"format": "twolink-pin identified parameters", "nv": 6, "robot": "ur5"}))
    with pytest.raises(
        InputFileError, match="says nv = 6 \\(robot 'ur5'\\); expected nv = 2, the joint count of twolink"
    ):
        read_parameter_file(path, twolink)


# --------------------------------------------------------------------------- the CLI


def test_cli_identify_says_when_the_3_sigma_count_tests_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    """On noise-free simulated data σ is rounding and filtering: the ±3σ count says so; with
    torque noise it is a test of σ and carries no such note."""
    short = ["identify", "--duration", "4", "--dt", "0.001"]
    assert main(short) == 0
    clean = capsys.readouterr().out.splitlines()[-1]
    assert clean.startswith("  true values within ±3σ:") and "noise-free data" in clean
    assert main([*short, "--noise-tau", "0.05"]) == 0
    noisy = capsys.readouterr().out.splitlines()[-1]
    assert noisy.startswith("  true values within ±3σ:") and "noise-free" not in noisy


def test_cli_identify_json_and_p0(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """identify --json is clean JSON with parameters (name, estimate, std, true) and the
    condition number; the saved file seeds simulate --p0; a CSV error is one line, exit 2."""
    saved = tmp_path / "p.json"
    code = main(
        [
            "identify",
            "--duration",
            "20",
            "--dt",
            "0.001",
            "--json",
            "--save",
            str(saved),
            "--noise-tau",
            "0.05",
        ]
    )
    out = capsys.readouterr().out
    assert code == 0
    document = json.loads(out)
    assert 2.0 < document["condition_number"] < 3.5  # the excitation's 2.39, from noisy closed-loop data
    assert {"name", "estimate", "std", "true"} <= set(document["parameters"][0])
    assert all(row["true"] is not None for row in document["parameters"])
    assert main(["simulate", "adaptive", "--p0", str(saved), "--duration", "0.1", "--json"]) == 0
    simulated = json.loads(capsys.readouterr().out)
    assert simulated["p_hat_final"][0] == pytest.approx(3.4, rel=0.01)
    bad = _csv(tmp_path / "bad.csv", [[0, 0, 0, 0]] * 20, header="t,q1,q2,tau1")
    assert main(["identify", "--data", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "missing column 'tau2'" in err[0]
    assert main(["simulate", "pd", "--p0", str(saved)]) == 2
    assert "estimates none" in capsys.readouterr().err


def test_cli_identify_from_a_csv_log_of_a_real_arm(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], twolink_log
) -> None:
    """--data reads t, q, tau (no truth: "true" is null) and refuses --duration with it."""
    path = write_log(
        tmp_path / "arm.csv", RunLog(twolink_log.t[::2], twolink_log.q[::2], twolink_log.tau[::2])
    )
    assert main(["identify", "--data", str(path), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert all(row["true"] is None for row in document["parameters"])
    estimate = np.array([row["estimate"] for row in document["parameters"]])
    assert _relative_errors(estimate, twolink_log.true_parameters).max() < 1e-5
    assert main(["identify", "--data", str(path), "--duration", "3"]) == 2
    assert "--duration = 3.0 is invalid: expected no value with --data" in capsys.readouterr().err


def test_cli_excite_reports_both_condition_numbers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "ex.json"
    assert main(["excite", "--out", str(out), "--starts", "1", "--max-iterations", "10", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["report_condition_number"] == pytest.approx(11.35, abs=0.01)
    assert document["condition_number"] < document["report_condition_number"]
    assert document["iterations"] == 10 and document["seconds"] > 0
    trajectory = read_trajectory_file(out, load_robot())
    assert excitation_measures(load_robot(), trajectory).condition_number == pytest.approx(
        document["condition_number"], rel=1e-12
    )


def test_cli_commands_take_a_fourier_trajectory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """trajectory, simulate and animate --html accept excite's file (no via points to show)."""
    path = write_trajectory_file(tmp_path / "ex.toml", twolink_excitation.identification_excitation())
    assert main(["trajectory", "--trajectory", str(path), "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["fourier"]["harmonics"] == 5 and document["within_limits"] is True
    assert document["condition_number"] == pytest.approx(2.386, abs=0.01)
    assert (
        main(["simulate", "computed-torque", "--trajectory", str(path), "--duration", "0.5", "--json"]) == 0
    )
    assert json.loads(capsys.readouterr().out)["metrics"]["rms"]["e"][0] < 0.1
    html = tmp_path / "a.html"
    assert main(["animate", "pd", "--trajectory", str(path), "--duration", "0.2", "--html", str(html)]) == 0
    assert html.stat().st_size > 1000


@pytest.mark.slow
def test_the_html_report_answers_figure_27(tmp_path: Path) -> None:
    """A 10-s report of the adaptive law: the identification section beside Fig. 27 has the three
    references, the adaptation excitation within 5 % in the run, an identification with its true
    values within ±3σ, and its figures on disk."""
    from twolink_pin.report import ReportOptions, build_report
    from twolink_pin.run_spec import RunSpec

    options = ReportOptions(
        run=RunSpec(simulation=SimulationConfig(duration=10.0)),
        workers=1,
        animation=False,
        limits_section=False,
        sim_to_sim=False,
        controllers=("adaptive",),
    )
    results = build_report(tmp_path / "r", options)
    section = results["identification"]
    assert [row["trajectory"] for row in section["table"]] == ["report", "identification", "adaptation"]
    assert section["runs"]["adaptation"]["time_within_5_percent_s"] < 10.0
    assert section["runs"]["report"]["time_within_5_percent_s"] is None
    assert section["identified"]["within_3_sigma"] == 8
    for name in section["figures"]:
        assert (tmp_path / "r" / "figures" / name).is_file()
    html = (tmp_path / "r" / "index.html").read_text()
    assert 'id="identification"' in html and "identification_convergence.png" in html
    assert html.index('id="ctrl-adaptive"') < html.index('id="identification"') < html.index('id="table2"')


@pytest.mark.slow
def test_the_docs_script_runs(tmp_path: Path) -> None:
    """scripts/identification_docs.py --quick writes the page's four figures and its numbers."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "identification_docs", Path(__file__).parents[1] / "scripts" / "identification_docs.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--out", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "identification_convergence.png",
        "identification_coverage.png",
        "identification_excitation.png",
        "identification_validation.png",
    ]


def test_the_summary_says_which_parameter_file_a_run_used(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``simulate --model`` / ``--p0``: the text names the file and what it did; the JSON too;
    without one, neither says anything."""
    saved = tmp_path / "p.json"
    assert main(["identify", "--duration", "3", "--save", str(saved), "--json"]) == 0
    capsys.readouterr()
    assert main(["simulate", "computed-torque", "--model", str(saved), "--duration", "0.05"]) == 0
    line = f"  law's model believes the parameters of {saved} (--model); the plant is twolink's own"
    assert line in capsys.readouterr().out.splitlines()
    assert main(["simulate", "adaptive", "--p0", str(saved), "--duration", "0.05", "--json"]) == 0
    used = json.loads(capsys.readouterr().out)["believed"]
    assert used == {"file": str(saved), "use": "p0"}
    assert main(["simulate", "adaptive", "--duration", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["believed"] is None
    out = tmp_path / "cmp"
    argv = ["compare", "pd", "computed-torque", "--model", str(saved), "--duration", "0.05", "--no-plot"]
    assert main([*argv, "--out", str(out)]) == 0
    assert line.strip() in capsys.readouterr().out.splitlines()
    assert main([*argv, "--out", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["believed"]["use"] == "model"
