"""The numbers and figures of docs/identification.md, measured.

Run from the repository root (headless, about two minutes on one core)::

    .venv/bin/python scripts/identification_docs.py            # writes docs/images/identification_*.png
    .venv/bin/python scripts/identification_docs.py --quick --out /tmp/x   # a smoke run (seconds)

It prints one JSON document with every number the page quotes: the excitations compared with
the report's trajectory (condition number, Gram eigenvalue, slowest averaged adaptation time
constant, predicted and simulated time to 5 %), the noise-free recovery on the twolink and the
UR5, and a Monte Carlo over noise seeds (coverage of ±3σ, scatter of the normalised errors) at
several noise levels, by least squares and by instrumental variables.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from twolink_pin import load_robot  # noqa: E402
from twolink_pin.identification import (  # noqa: E402
    IdentificationOptions,
    add_noise,
    averaged_adaptation,
    identify,
    simulate_log,
)
from twolink_pin.identification.excitation import ExcitationLimits  # noqa: E402
from twolink_pin.plotting.identification import (  # noqa: E402
    save_convergence_figure,
    save_coverage_figure,
    save_excitation_figures,
    save_identification_figures,
)
from twolink_pin.trajectory import read_trajectory_file  # noqa: E402
from twolink_pin.twolink import excitation as twolink_excitation  # noqa: E402

NOISE_LEVELS = ((0.0, 0.05), (1e-5, 0.05), (1e-4, 0.05), (1e-3, 0.05), (1e-4, 0.5))
"""(σ_q [rad], σ_τ [N·m]) of the Monte Carlo."""


def relative(estimate: np.ndarray, true: np.ndarray) -> float:
    return float(np.max(np.abs(estimate - true) / np.where(np.abs(true) > 0, np.abs(true), 1.0)))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "images"), help="folder of the figures")
    parser.add_argument("--quick", action="store_true", help="few seeds, short runs (a smoke test)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    seeds = 5 if args.quick else 200
    duration = 2.0 if args.quick else 30.0
    numbers: dict[str, object] = {}
    robot = load_robot("twolink")

    # 1. The report's question: the three references compared.
    numbers["excitations"] = twolink_excitation.excitation_table(robot)
    runs = twolink_excitation.adaptive_runs(robot, duration=duration)
    controller = twolink_excitation.report_adaptive(robot).controller
    p = np.asarray(robot.p)
    panels, simulated = {}, {}
    for key, result in runs.items():
        within = twolink_excitation.time_within(result.t, result.p_hat, p)
        averaged = averaged_adaptation(controller, twolink_excitation.trajectories(robot)[key])
        t_pred = np.linspace(0.0, duration, 301)
        panels[twolink_excitation.TITLES[key]] = {
            "t": result.t,
            "p_hat": result.p_hat,
            "p_true": p,
            "names": list(robot.parameter_map.names),
            "predicted": (t_pred, averaged.predicted_error(result.p_hat[0] - p, t_pred)),
            "time_within": within,
            "note": f"averaged slowest time constant {averaged.slowest_time_constant:.3g} s",
        }
        simulated[key] = {
            "time_within_5_percent_s": within,
            "relative_error_final": (np.abs(result.p_hat[-1] - p) / p).tolist(),
        }
    numbers["adaptive_runs"] = simulated
    save_convergence_figure(panels, out / "identification_convergence.png")
    limits = {k: v.tolist() for k, v in ExcitationLimits().resolve(robot).items()}
    excitation = twolink_excitation.identification_excitation()
    (out / "excitation.png").unlink(missing_ok=True)
    save_excitation_figures(robot, excitation, out, limits=limits)
    (out / "excitation.png").replace(out / "identification_excitation.png")

    # 2. Noise-free recovery.
    log = simulate_log(robot, excitation, duration=3.0 if args.quick else 40.0)
    found = identify(log, robot)
    numbers["twolink_noise_free"] = {
        "max_relative_error": relative(found.estimate, found.true),
        "condition_number": found.condition_number,
        "validation_rms": found.validation.rms.tolist() if found.validation else None,
    }
    ur5 = load_robot("ur5")
    ur5_trajectory = read_trajectory_file(ROOT / "tests" / "fixtures" / "ur5_excitation.json", ur5)
    ur5_log = simulate_log(ur5, ur5_trajectory, 2.0 if args.quick else 20.0)
    ur5_found = identify(ur5_log, ur5, IdentificationOptions(validation=0.0))
    numbers["ur5_noise_free"] = {
        "parameters": ur5_found.size,
        "max_relative_error": relative(ur5_found.estimate, ur5_found.true),
        "condition_number": ur5_found.condition_number,
    }
    noisy = identify(add_noise(log, 1e-4, 0.05, 0), robot)
    numbers["twolink_noisy_example"] = {
        "parameters": noisy.parameters(),
        "condition_number": noisy.condition_number,
        "validation_rms": noisy.validation.rms.tolist() if noisy.validation else None,
        "method": noisy.method,
    }
    written = save_identification_figures(noisy, out, prefix="identification_")
    (out / "identification_estimates.png").unlink(missing_ok=True)
    assert written

    # 3. The Monte Carlo.
    mc_log = simulate_log(robot, excitation, duration=3.0 if args.quick else 20.0, dt=1e-3)
    monte_carlo = []
    for noise_q, noise_tau in NOISE_LEVELS[2:3] if args.quick else NOISE_LEVELS:
        for instruments in (True, False):
            options = IdentificationOptions(validation=0.0, instruments=instruments)
            started = time.perf_counter()
            z = np.array(
                [
                    (r.estimate - r.true) / r.std
                    for r in (
                        identify(add_noise(mc_log, noise_q, noise_tau, seed), robot, options)
                        for seed in range(seeds)
                    )
                ]
            )
            inside = np.abs(z) <= 3
            monte_carlo.append(
                {
                    "noise_q_rad": noise_q,
                    "noise_tau_Nm": noise_tau,
                    "method": "instrumental variables" if instruments else "least squares",
                    "seeds": seeds,
                    "coverage_3_sigma": float(inside.mean()),
                    "worst_parameter_coverage": float(inside.mean(axis=0).min()),
                    "z_std_range": [float(z.std(axis=0).min()), float(z.std(axis=0).max())],
                    "worst_mean_z": float(np.abs(z.mean(axis=0)).max()),
                    "seconds": time.perf_counter() - started,
                }
            )
            if (noise_q, noise_tau, instruments) == (1e-4, 0.05, True):
                save_coverage_figure(
                    z,
                    list(found.names),
                    out / "identification_coverage.png",
                    title=f"{seeds} noise seeds, σ_q = 1e-4 rad, σ_τ = 0.05 N·m, 20-s log, instrumental variables: "
                    "is the stated σ honest?",
                )
    numbers["monte_carlo"] = monte_carlo
    print(json.dumps(numbers, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
