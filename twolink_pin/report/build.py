"""``twolink-pin report``: run everything and write the report folder.

Output in ``out_dir``: ``index.html`` (opens from ``file://``, no external request),
``report.md``, ``comparison.csv``, ``results.json``, ``figures/*.png`` and
``animation.html``. For the twolink the page follows the course report (Table 1, its
via points and coefficients, its Table 2 beside ours, the errata); for any other robot it
shows the same pipeline without the report's sections.

The folder is built in a staging folder and moved into place only when complete
(:func:`twolink_pin.files.output_directory`), so a failure, Ctrl-C or SIGTERM midway
leaves the previous report (or nothing) — never a half-written ``index.html`` and no
worker process behind.
"""

from __future__ import annotations

import inspect
import os
import signal
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import (
    ControllerError,
    InvalidParameterError,
    InvalidURDFError,
    SimulationDivergedError,
)
from twolink_pin.feasibility import check_torques
from twolink_pin.files import output_directory
from twolink_pin.metrics import Metrics, compute_metrics
from twolink_pin.model import load_robot
from twolink_pin.report import facts
from twolink_pin.run_spec import RunSpec
from twolink_pin.scenario import builtin_laws, law_class, make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.simulation.config import joint_offsets
from twolink_pin.studies.comparison import ComparisonTable
from twolink_pin.trajectory import default_trajectory, default_via_points

MARKER = ".twolink-pin-report"
"""File that marks a directory as written by this command (safe to replace)."""
MAX_WORKERS = 64
"""Largest number of worker processes (more than the runs is never used)."""
ANIMATED = "adaptive"
"""The law whose run the report animates (the first law if it is not run)."""

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True)
class ReportOptions:
    """What the report runs.

    Attributes:
        run: The runs' common description (:class:`~twolink_pin.run_spec.RunSpec`, shared by
            the laws: each law's own with :meth:`~twolink_pin.run_spec.RunSpec.for_law`):
            simulation settings, λ of the laws that have one, per-law gains, the plant, an
            identified-parameter file (``p0``: the estimates of the laws that estimate start
            there; ``model``: every law's model believes it).
        robot: A catalog name or a URDF path; None for the twolink.
        payload: End-effector payload [kg].
        controllers: The laws to run (names, ``file.py:Class``, ``module:Class``); None for
            the course report's five on the twolink, every built-in law elsewhere.
        workers: Processes for the runs and figures (1: in this process), 1 to 64.
        animation: Whether to write the self-contained animation.
        identification: Whether the twolink's report has its identification section (beside
            Fig. 27: the adaptive law along two excitations and an identification; about
            14 s of CPU: without it the report takes 11–13 s on 2 cores instead of 17–19 s).
        trajectory: A trajectory file (:func:`~twolink_pin.trajectory.read_trajectory_file`)
            to track instead of the robot's default; the twolink's sections about the
            report's own trajectory (Table 1, the printed coefficients) then still describe
            the report's.
    """

    run: RunSpec = field(default_factory=lambda: RunSpec(shared=True))
    robot: str | None = None
    payload: float = 0.0
    controllers: tuple[str, ...] | None = None
    workers: int = 2
    animation: bool = True
    identification: bool = True
    trajectory: str | None = None

    @property
    def config(self) -> SimulationConfig:
        """The simulation settings of every run."""
        return self.run.simulation

    @property
    def lam(self) -> float | None:
        """λ [1/s] of the laws that have one (None: their default)."""
        return self.run.lam

    @property
    def saturate(self) -> bool:
        """Whether every plant clips torques at the URDF limits."""
        return self.run.plant.saturate

    @property
    def friction_smoothing(self) -> float:
        """ε [rad/s] of the friction sign."""
        return self.run.friction_smoothing

    @property
    def p0(self) -> str | None:
        """The parameter file the estimates start at, if any."""
        return self.run.parameters if self.run.parameters_use == "p0" else None

    @property
    def model(self) -> str | None:
        """The parameter file every law's model believes, if any."""
        return self.run.parameters if self.run.parameters_use == "model" else None

    def __post_init__(self) -> None:
        if not (
            isinstance(self.workers, int)
            and not isinstance(self.workers, bool)
            and 1 <= self.workers <= MAX_WORKERS
        ):
            raise InvalidParameterError("workers", self.workers, f"a whole number from 1 to {MAX_WORKERS}")
        if not isinstance(self.run, RunSpec):
            raise InvalidParameterError("run", type(self.run).__name__, "a RunSpec")
        if not self.run.shared:  # one description for several laws: λ and p0 go where they apply
            object.__setattr__(self, "run", replace(self.run, shared=True))


def _reference(robot: Any, options: ReportOptions) -> Any:
    """The trajectory the runs track: the options' file, else the robot's default."""
    from twolink_pin.trajectory import read_trajectory_file

    reference = (
        read_trajectory_file(options.trajectory, robot) if options.trajectory else default_trajectory(robot)
    )
    if not hasattr(reference, "via_q"):
        raise InvalidParameterError(
            "trajectory",
            options.trajectory,
            "a via-point trajectory file (the report shows its via points and coefficients); a Fourier "
            "excitation is for identify --trajectory, simulate, compare and animate",
        )
    return reference


def _run(
    spec: str,
    options: ReportOptions,
    fig_dir: str,
    figure_numbers: dict[str, int] | None,
) -> tuple[SimulationResult, Metrics, list[str], float]:
    """Worker: one law's run, metrics and figures (picklable arguments only)."""
    from twolink_pin.plotting import save_simulation_figures

    start = time.perf_counter()
    robot = load_robot(options.robot, payload=options.payload)
    cls = law_class(spec)
    controller, plant = options.run.for_law(spec).build(robot)
    result = simulate(controller, plant, _reference(robot, options), options.config)
    metrics = compute_metrics(result)
    paths = save_simulation_figures(
        result, Path(fig_dir), prefix=cls.name, figure_numbers=figure_numbers, title=cls.title
    )
    return result, metrics, [Path(p).name for p in paths], time.perf_counter() - start


def _trajectory_figures(
    options: ReportOptions, fig_dir: str, figure_numbers: dict[str, int] | None
) -> list[str]:
    """Worker: the desired trajectory's figures (picklable arguments only)."""
    from twolink_pin.plotting import save_trajectory_figures

    robot = load_robot(options.robot, payload=options.payload)
    trajectory = _reference(robot, options)
    check = check_torques(robot, trajectory)
    paths = save_trajectory_figures(robot, trajectory, check, Path(fig_dir), figure_numbers=figure_numbers)
    return [p.name for p in paths]


class _InProcess:
    """A stand-in for ProcessPoolExecutor that runs each task at submit (workers = 1)."""

    def __enter__(self) -> _InProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        future: Future[Any] = Future()
        try:
            future.set_result(fn(*args))
        except Exception as exc:
            future.set_exception(exc)
        return future

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        return None


@contextmanager
def _pool(workers: int) -> Iterator[Any]:
    """Worker processes that never outlive the report: on an error, Ctrl-C or SIGTERM the
    pending runs are cancelled and the workers killed before the exception goes on."""
    if workers <= 1:
        with _InProcess() as serial:
            yield serial
        return
    pool = ProcessPoolExecutor(max_workers=workers)
    previous = signal.getsignal(signal.SIGTERM)

    def _terminate(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    in_main = _is_main_thread()
    if in_main:
        signal.signal(signal.SIGTERM, _terminate)
    try:
        yield pool
    except BaseException:
        processes = list(getattr(pool, "_processes", {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            if process.is_alive():
                process.kill()
        for process in processes:
            process.join(timeout=5)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)


def _is_main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def laws_to_run(options: ReportOptions, is_twolink: bool) -> tuple[str, ...]:
    """The laws the report runs (see :class:`ReportOptions`)."""
    if options.controllers is not None:
        names = tuple(law_class(spec).name for spec in options.controllers)
        if len(set(names)) != len(names):
            raise InvalidParameterError("controllers", list(options.controllers), "each law at most once")
        return tuple(options.controllers)
    if is_twolink:
        from twolink_pin.twolink.reference import REPORT_CONTROLLERS

        return REPORT_CONTROLLERS
    return builtin_laws()


def build_report(
    out_dir: str | os.PathLike[str],
    options: ReportOptions | None = None,
    progress: Progress | None = None,
    command_line: str = "",
) -> dict[str, Any]:
    """Write the report into ``out_dir``; returns the ``results.json`` content.

    Raises:
        OutputError: ``out_dir`` is a file or a non-empty directory that holds no report,
            or it cannot be written.
        SimulationDivergedError, ControllerError: a run failed (the message names the law
            and the time); nothing is written.
    """
    options = options if options is not None else ReportOptions()
    started = time.perf_counter()
    robot = load_robot(options.robot, payload=options.payload)
    is_twolink = robot.name == "twolink"
    specs = laws_to_run(options, is_twolink)
    options.run.check_law_gains(specs)
    steps = (
        4 + len(specs) + (1 if options.animation else 0) + (1 if is_twolink and options.identification else 0)
    )
    done = 0

    def tick(what: str) -> None:
        nonlocal done
        done += 1
        if progress:
            progress(what, done, steps)

    with output_directory(out_dir, MARKER, "written by twolink-pin report\n") as stage:
        results = _build(stage, robot, is_twolink, specs, options, tick)
        results["total_seconds"] = time.perf_counter() - started
        results["command_line"] = command_line
        from twolink_pin.report.pages import write_pages

        write_pages(stage, results)
        tick("done")
    return results


def _build(
    stage: Path,
    robot: Any,
    is_twolink: bool,
    specs: Sequence[str],
    options: ReportOptions,
    tick: Callable[[str], None],
) -> dict[str, Any]:
    fig_dir = stage / "figures"
    fig_dir.mkdir()
    trajectory = _reference(robot, options)
    via = default_via_points(robot) if not options.trajectory else None
    check = check_torques(robot, trajectory)
    numbers: dict[str, dict[str, int]] = {}
    if is_twolink:
        from twolink_pin.twolink.reference import REPORT_FIGURES

        numbers = REPORT_FIGURES
    names = [law_class(spec).name for spec in specs]
    animated = ANIMATED if ANIMATED in names else names[0]
    order = [animated, *(n for n in names if n != animated)]
    by_name = dict(zip(names, specs))
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]] = {}
    failed: dict[str, str] = {}
    warnings: list[str] = []
    tried, shown = False, animated
    animation = None
    workers = min(options.workers, len(order) + 1)
    with _pool(workers) as pool:
        # The identification's runs first: they are the longest tasks (3 adaptive runs and a
        # logged run of 30 s), so the laws' runs fill the other worker meanwhile.
        reused = "adaptive" in names and _reuses_adaptive_run(options)
        ident_futures = (
            _submit_identification(pool, options, str(fig_dir), reused)
            if is_twolink and options.identification
            else None
        )
        futures = {n: pool.submit(_run, by_name[n], options, str(fig_dir), numbers.get(n)) for n in order}
        traj_future = pool.submit(_trajectory_figures, options, str(fig_dir), numbers.get("trajectory"))
        model = facts.model_facts(robot)
        twolink: dict[str, Any] | None = None
        if is_twolink:
            twolink = {
                "closed_form_check": facts.twolink_closed_form_check(robot),
                "table1": None if via is None else facts.table1(robot, via),  # None: another trajectory
            }
        tick("model and trajectory")
        for name in order:
            try:
                runs[name] = futures[name].result()
            except (SimulationDivergedError, ControllerError) as exc:  # the others' results are kept
                failed[name] = str(exc)
            tick(f"controller {name}")
            if options.animation and not tried and name in runs and (name == animated or animated in failed):
                from twolink_pin.visualization import write_html

                tried, shown = True, name
                res = runs[name][0]
                from twolink_pin.kinematics import joint_positions

                points = joint_positions(robot, trajectory.via_q)[:, -1, :]  # the end effector's via points
                try:
                    write_html(
                        robot, res.t, res.q, res.q_des, path=stage / "animation.html", via_points=points
                    )
                    animation = "animation.html"
                except InvalidURDFError as exc:  # a missing mesh: the report without its animation
                    warnings.append(f"no animation: {exc}")
                tick("animation")
        if options.animation and not tried:
            tick("animation")  # every law failed: nothing to animate
        traj_figs = traj_future.result()
        tick("trajectory figures")
        identification = None
        if ident_futures is not None:
            runs_future, fit_future = ident_futures
            excitation_runs = {key: f.result() for key, f in runs_future.items()}
            if reused and "adaptive" in runs:  # the report's own adaptive run is the one along its trajectory
                result = runs["adaptive"][0]
                assert result.p_hat is not None
                own = (np.asarray(result.t), np.asarray(result.p_hat)[:, : np.asarray(robot.p).size])
                excitation_runs = {"report": own, **excitation_runs}
            identification = _identification_section(
                options,
                str(fig_dir),
                excitation_runs,
                None if fit_future is None else fit_future.result(),
            )
            tick("identification")
    runs = {n: runs[n] for n in names if n in runs}  # the order asked for
    table = ComparisonTable(
        {n: r[1] for n, r in runs.items()},
        {n: r[3] for n, r in runs.items()},
        options.config.duration,
        {n: failed[n] for n in names if n in failed},
    )
    cfg = options.config
    q0_offset = joint_offsets("q0_offset", cfg.q0_offset, robot.profile.q0_offset, robot.nv)
    controllers = {}
    lams: dict[str, float] = {}
    for name, (result, metrics, figures, seconds) in runs.items():
        cls = law_class(by_name[name])
        controller = options.run.for_law(by_name[name]).build(robot).controller  # the gains it ran with
        if cls.takes("lam"):
            lams[name] = float(np.max(controller.gains.lam))
        controllers[name] = {
            "title": cls.title,
            "law": inspect.getdoc(cls) or "",
            "gains": controller.gains.describe(),
            "metrics": metrics.as_dict(),
            "figures": figures,
            "seconds": seconds,
            "p_hat_final": None if result.p_hat is None else result.p_hat[-1].tolist(),
            "p_true": None if result.p_true is None else result.p_true.tolist(),
            "parameter_names": list(result.parameter_names),
            "limit_exceeded": result.limit_exceeded.tolist(),
            "limit_exceeded_at": result.first_exceeded_at,
        }
    errata: list[dict[str, Any]] = []
    if is_twolink:
        lam = next(iter(lams.values()), 5.0)
        errata = _twolink_errata(robot, trajectory, runs, by_name, options, q0_offset, lam)
    tick("errata")
    out: dict[str, Any] = {
        "robot": model,
        "twolink": twolink,
        "trajectory": {
            "times": trajectory.times.tolist(),
            "via_q": trajectory.via_q.tolist(),
            "via_xy": None if via is None else [list(p) for p in via.xy],
            "period_s": trajectory.period,
            "coefficients": trajectory.coefficients.tolist(),
            "figures": traj_figs,
        },
        "torque_check": facts.torque_facts(check),
        "simulation": asdict(cfg)
        | {
            "q0_offset": q0_offset.tolist(),
            "lambda": lams,
            "saturate": options.saturate,
            "friction_smoothing": options.friction_smoothing,
        },
        "run": options.run.as_dict(),
        "controllers": controllers,
        "failed": table.failed,
        "comparison": table.as_dict(),
        "comparison_markdown": table.markdown(),
        "comparison_csv": table.csv(),
        "animation": animation,
        "warnings": warnings,
        "animated": shown,
        "errata": errata,
        "identification": identification,
        "versions": facts.versions(),
    }
    if is_twolink:
        from twolink_pin.twolink.reference import (
            REPORT_COEFFICIENTS,
            REPORT_P,
            REPORT_TABLE2,
            REPORT_TABLE2_COLUMNS,
        )

        assert twolink is not None
        twolink["report_p"] = REPORT_P
        twolink["report_coefficients"] = [list(c) for c in REPORT_COEFFICIENTS]
        twolink["report_table2"] = {n: list(v) for n, v in REPORT_TABLE2.items()}
        twolink["report_table2_columns"] = list(REPORT_TABLE2_COLUMNS)
    return out


IDENTIFICATION_NOISE = (1e-5, 0.05)
"""Noise of the report's identification example: σ_q [rad] (encoder level), σ_τ [N·m]."""


def _finite(x: Any) -> Any:
    """``x`` with non-finite floats as None (results.json is strict JSON)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if np.isfinite(x) else None
    return x


def _reuses_adaptive_run(options: ReportOptions) -> bool:
    """Whether the report's ``adaptive`` run is exactly the identification section's run
    along the report's trajectory (same law, gains, p̂(0), reference and simulation)."""
    from twolink_pin.simulation import SimulationConfig

    return (
        options.trajectory is None
        and options.p0 is None
        and options.model is None
        and options.lam is None
        and not options.saturate
        and options.friction_smoothing == 0.0
        and options.config == SimulationConfig(duration=options.config.duration)
    )


def _submit_identification(
    pool: Any, options: ReportOptions, fig_dir: str, reused: bool
) -> tuple[dict[str, Any], Any] | None:
    """Submit the identification section's tasks: the report's adaptive law along each
    reference (one task each; not along the report's trajectory when ``reused``: the
    report's own adaptive run is that one) and the identification from a logged run."""
    from twolink_pin.twolink import excitation as twolink_excitation

    if options.config.duration < twolink_excitation.PERIOD:
        return {}, None
    keys = [key for key in twolink_excitation.TRAJECTORIES if not (reused and key == "report")]
    runs = {key: pool.submit(_excitation_run, options, key) for key in keys}
    return runs, pool.submit(_identification_fit, options, fig_dir)


def _excitation_run(options: ReportOptions, key: str) -> tuple[np.ndarray, np.ndarray]:
    """Worker: the report's adaptive law along the reference ``key``: ``(t [s], p̂)``."""
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = load_robot(options.robot, payload=options.payload)
    result = twolink_excitation.adaptive_runs(robot, duration=options.config.duration, keys=(key,))[key]
    assert result.p_hat is not None
    return np.asarray(result.t), np.asarray(result.p_hat)[:, : np.asarray(robot.p).size]


def _identification_fit(options: ReportOptions, fig_dir: str) -> tuple[list[str], dict[str, Any]]:
    """Worker: identification from one noisy logged run along the identification excitation,
    its figures and its numbers."""
    from twolink_pin.identification import (
        ExcitationLimits,
        IdentifiedParameters,
        add_noise,
        identify,
        map_parameters,
        simulate_log,
    )
    from twolink_pin.plotting.identification import save_excitation_figures, save_identification_figures
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = load_robot(options.robot, payload=options.payload)
    p = np.asarray(robot.p, dtype=float)
    log = simulate_log(
        robot, twolink_excitation.identification_excitation(), duration=options.config.duration
    )
    noisy = add_noise(log, *IDENTIFICATION_NOISE, seed=0)
    found = identify(noisy, robot)
    figures = list(save_identification_figures(found, fig_dir))
    limits = ExcitationLimits().resolve(robot)
    figures += save_excitation_figures(
        robot,
        twolink_excitation.identification_excitation(),
        fig_dir,
        limits={k: v.tolist() for k, v in limits.items()},
    )
    nb = found.size - 2 * robot.nv
    identified = IdentifiedParameters("report", found.estimate[:nb], found.std[:nb], None)
    p_identified = map_parameters(robot, identified)
    inside = found.within()
    numbers = {
        "noise": {"q_rad": IDENTIFICATION_NOISE[0], "tau_Nm": IDENTIFICATION_NOISE[1], "seed": 0},
        "parameters": found.parameters(),
        "condition_number": found.condition_number,
        "validation_rms": None if found.validation is None else found.validation.rms.tolist(),
        "fit_samples": found.fit_samples,
        "cutoff_hz": found.cutoff_hz,
        "within_3_sigma": None if inside is None else int(np.sum(inside)),
        "method": found.method,
        "p": p_identified.tolist(),
        "p_relative_error": (np.abs(p_identified - p) / np.abs(p)).tolist(),
    }
    return [str(f) for f in figures], numbers


def _identification_section(
    options: ReportOptions,
    fig_dir: str,
    runs: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
    fit: tuple[list[str], dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """The report's question answered beside Figure 27 (the twolink only): why the adaptive
    estimates are still far from p at the end of the run, the excitations that fix it, and
    what identification gives from one run of the same length. ``runs`` (key → (t, p̂)) and
    ``fit`` are the results of :func:`_excitation_run` and :func:`_identification_fit`, run
    here when not given.

    The adaptive runs and the identification need a run of at least one excitation period;
    shorter reports show the table only."""
    from twolink_pin.identification.measures import averaged_adaptation
    from twolink_pin.plotting.identification import save_convergence_figure
    from twolink_pin.twolink import excitation as twolink_excitation

    robot = load_robot(options.robot, payload=options.payload)
    duration = options.config.duration
    section: dict[str, Any] = {
        "table": twolink_excitation.excitation_table(robot),
        "duration_s": duration,
        "period_s": twolink_excitation.PERIOD,
        "figures": [],
        "runs": {},
        "identified": None,
        "note": None,
    }
    if duration < twolink_excitation.PERIOD:
        section["note"] = (
            f"runs of {duration:g} s are shorter than one excitation period ({twolink_excitation.PERIOD:g} s): "
            "the adaptive runs along the excitations and the identification are left out"
        )
        return _finite(section)
    if not runs:
        runs = {key: _excitation_run(options, key) for key in twolink_excitation.TRAJECTORIES}
    if fit is None:
        fit = _identification_fit(options, fig_dir)
    controller = twolink_excitation.report_adaptive(robot).controller
    p = np.asarray(robot.p, dtype=float)
    panels = {}
    for key, (t, p_hat) in runs.items():
        within = twolink_excitation.time_within(t, p_hat, p)
        averaged = averaged_adaptation(controller, twolink_excitation.trajectories(robot)[key])
        t_pred = np.linspace(0.0, duration, 301)
        predicted = averaged.predicted_error(p_hat[0] - p, t_pred)
        section["runs"][key] = {
            "title": twolink_excitation.TITLES[key],
            "p_hat_final": p_hat[-1].tolist(),
            "relative_error_final": (np.abs(p_hat[-1] - p) / np.abs(p)).tolist(),
            "time_within_5_percent_s": within,
        }
        panels[twolink_excitation.TITLES[key]] = {
            "t": t,
            "p_hat": p_hat,
            "p_true": p,
            "names": list(robot.parameter_map.names),
            "predicted": (t_pred, predicted),
            "time_within": within,
            "note": f"averaged slowest time constant {averaged.slowest_time_constant:.3g} s",
        }
    figures: list[str | Path] = [
        save_convergence_figure(
            panels,
            Path(fig_dir) / "identification_convergence.png",
            title="the report's adaptive law (K = 120, γ = (0.5, 0.15, 0.6)) along three references — cf. report "
            "Fig. 27\n|p̂ − p| / |p| (solid: simulated; dotted: averaged model exp(−ΓG t))",
        ),
        *fit[0],
    ]
    section["identified"] = fit[1]
    section["figures"] = [Path(f).name for f in figures]
    return _finite(section)


def _twolink_errata(
    robot: Any,
    trajectory: Any,
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]],
    by_name: dict[str, str],
    options: ReportOptions,
    q0_offset: np.ndarray,
    lam: float,
) -> list[dict[str, Any]]:
    from twolink_pin.twolink import errata

    report_trajectory = default_trajectory(robot)  # the errata are about the report's own trajectory
    items = [
        errata.third_via_point(robot),
        errata.printed_coefficients(report_trajectory),
        errata.y3_sign(robot),
    ]
    items.append(errata.unstated_settings(lam, tuple(q0_offset.tolist())))
    if "robust" in runs:
        items.append(errata.robust_naming(runs["robust"][0]))
    if "adaptive" in runs:
        cls = law_class(by_name["adaptive"])
        controller = make_scenario(cls, robot, lam=options.lam).controller
        items.append(errata.parameter_convergence(runs["adaptive"][0], controller, trajectory))  # type: ignore[arg-type]
    return [e._asdict() for e in items]
