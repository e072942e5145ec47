"""``twolink-pin report``: the whole course report reproduced as one HTML page.

Sections follow the report's order: model, kinematics (Table 1), trajectory (Figures
3–6), the five controllers (Figures 7–34), Table 2, the animation, errata, and how the
page was made. Output in ``out_dir``: ``index.html`` (opens from ``file://``, no external
request), ``report.md``, ``table2.csv``, ``results.json``, ``figures/*.png`` and
``animation.html``.

The page is built in a staging directory beside ``out_dir`` and moved into place only
when complete, so a failure midway leaves the previous report (or nothing) — never a
half-written ``index.html``. An existing ``out_dir`` is replaced only if it is empty or
holds an earlier report (marker file :data:`MARKER`).
"""

from __future__ import annotations

import html
import inspect
import os
import platform
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.comparison import COLUMNS, REPORT_TABLE2, UNITS, Table2
from twolink_pin.controllers import CONTROLLERS
from twolink_pin.dynamics import coriolis_matrix, mass_matrix
from twolink_pin.errors import OutputError
from twolink_pin.feasibility import TorqueCheck, check_torques
from twolink_pin.files import atomic_write, write_json
from twolink_pin.kinematics import inverse_kinematics
from twolink_pin.metrics import Metrics, compute_metrics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.scenarios import make_scenario
from twolink_pin.simulation import SimulationConfig, SimulationResult, simulate
from twolink_pin.trajectory import ViaPoints, build_trajectory
from twolink_pin.twolink import errata
from twolink_pin.twolink.closed_form import coriolis_matrix as cf_coriolis
from twolink_pin.twolink.closed_form import mass_matrix as cf_mass

MARKER = ".twolink-pin-report"
"""File that marks a directory as written by this command (safe to replace)."""

ANIMATED_CONTROLLER = "adaptive"
"""Controller whose run the report animates."""

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True)
class ReportOptions:
    """What the report runs.

    Attributes:
        urdf: URDF file; None for the shipped twolink.
        payload: End-effector payload [kg].
        config: Simulation settings of the five runs.
        lam: λ [1/s] of the Slotine–Li laws (None: 5).
        workers: Processes for the five runs (1: in this process).
        animation: Whether to write the self-contained animation.
    """

    urdf: str | None = None
    payload: float = 0.0
    config: SimulationConfig = field(default_factory=SimulationConfig)
    lam: float | None = None
    workers: int = 2
    animation: bool = True


def _check_out_dir(out_dir: Path) -> None:
    if out_dir.exists():
        if not out_dir.is_dir():
            raise OutputError(str(out_dir), "exists and is not a directory")
        if any(out_dir.iterdir()) and not (out_dir / MARKER).exists():
            raise OutputError(
                str(out_dir),
                f"is a non-empty directory that holds no earlier report ({MARKER} missing); refusing to overwrite",
            )


def _run(
    name: str, urdf: str | None, payload: float, config: SimulationConfig, lam: float | None, fig_dir: str
):
    """Worker: one controller's run, metrics and figures (picklable arguments only)."""
    from twolink_pin.plotting import save_simulation_figures

    start = time.perf_counter()
    robot = load_robot(urdf, payload=payload)
    controller, plant = make_scenario(name, robot, lam=lam)
    result = simulate(controller, plant, build_trajectory(robot), config)
    metrics = compute_metrics(result)
    figures = [Path(p).name for p in save_simulation_figures(result, Path(fig_dir))]
    return result, metrics, figures, time.perf_counter() - start


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


def build_report(
    out_dir: str | os.PathLike[str],
    options: ReportOptions | None = None,
    progress: Progress | None = None,
    command_line: str = "",
) -> dict[str, Any]:
    """Write the report into ``out_dir``; returns the ``results.json`` content.

    Raises:
        OutputError: ``out_dir`` is a file or a non-empty directory that holds no report.
    """
    options = options if options is not None else ReportOptions()
    out = Path(out_dir)
    _check_out_dir(out)
    started = time.perf_counter()
    steps = 4 + len(CONTROLLERS) + (1 if options.animation else 0)
    done = 0

    def tick(what: str) -> None:
        nonlocal done
        done += 1
        if progress:
            progress(what, done, steps)

    out.parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
    try:
        results = _build(stage, options, tick)
        results["total_seconds"] = time.perf_counter() - started
        results["command_line"] = command_line
        _write_pages(stage, results)
        (stage / MARKER).write_text("written by twolink-pin report\n", encoding="utf-8")
        tick("done")
        _swap_into_place(stage, out)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    return results


def _swap_into_place(stage: Path, out: Path) -> None:
    old = None
    if out.exists():
        old = out.parent / f".{out.name}.old-{os.getpid()}"
        os.replace(out, old)
    os.replace(stage, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _trajectory_figures(urdf: str | None, payload: float, fig_dir: str) -> list[str]:
    """Worker: Figures 3–6 (picklable arguments only)."""
    from twolink_pin.plotting import save_trajectory_figures

    robot = load_robot(urdf, payload=payload)
    trajectory = build_trajectory(robot)
    check = check_torques(robot, trajectory)
    return [p.name for p in save_trajectory_figures(robot, trajectory, check, Path(fig_dir))]


def _build(stage: Path, options: ReportOptions, tick: Callable[[str], None]) -> dict[str, Any]:
    fig_dir = stage / "figures"
    robot = load_robot(options.urdf, payload=options.payload)
    via = ViaPoints()
    trajectory = build_trajectory(robot, via)
    check = check_torques(robot, trajectory)
    # The animated run first (the animation is written here while the workers plot),
    # the trajectory figures last; this process meanwhile checks the model.
    order = [ANIMATED_CONTROLLER, *(n for n in CONTROLLERS if n != ANIMATED_CONTROLLER)]
    run_args = {
        n: (n, options.urdf, options.payload, options.config, options.lam, str(fig_dir)) for n in order
    }
    traj_args = (options.urdf, options.payload, str(fig_dir))
    runs: dict[str, tuple[SimulationResult, Metrics, list[str], float]] = {}
    animation = None
    with ProcessPoolExecutor(max_workers=options.workers) if options.workers > 1 else _InProcess() as pool:
        futures = {n: pool.submit(_run, *a) for n, a in run_args.items()}
        traj_future = pool.submit(_trajectory_figures, *traj_args)
        model_section = _model_facts(robot)
        tick("model and trajectory")
        for name in order:
            runs[name] = futures[name].result()
            tick(f"controller {name}")
            if name == ANIMATED_CONTROLLER and options.animation:
                from twolink_pin.visualization import write_html

                res = runs[name][0]
                write_html(robot, res.t, res.q, res.q_des, path=stage / "animation.html", via_xy=via.xy)
                animation = "animation.html"
                tick("animation")
        traj_figs = traj_future.result()
        tick("trajectory figures")
    runs = {n: runs[n] for n in CONTROLLERS}  # the report's order
    table = Table2({n: r[1] for n, r in runs.items()}, {n: r[3] for n, r in runs.items()})

    cfg = options.config
    lam = options.lam if options.lam is not None else 5.0
    items = [
        errata.third_via_point(robot),
        errata.printed_coefficients(trajectory),
        errata.y3_sign(robot),
        errata.unstated_settings(lam, cfg.q0_offset),
        errata.robust_naming(runs["robust"][0]),
        errata.parameter_convergence(runs["adaptive"][0], robot, trajectory),
    ]
    tick("errata")
    return {
        "model": model_section,
        "table1": _table1(robot, via),
        "trajectory": {
            "times": trajectory.times.tolist(),
            "via_xy": [list(p) for p in via.xy],
            "via_q": trajectory.via_q.tolist(),
            "coefficients": trajectory.coefficients.tolist(),
            "report_coefficients": [list(c) for c in errata.REPORT_COEFFICIENTS],
            "figures": traj_figs,
        },
        "torque_check": _torque_facts(check),
        "simulation": {k: v for k, v in asdict(cfg).items()} | {"lambda": lam},
        "controllers": {
            name: {
                "law": inspect.getdoc(CONTROLLERS[name]) or "",
                "gains": _gains(r[0]),
                "metrics": r[1].as_dict(),
                "figures": r[2],
                "seconds": r[3],
                "p_hat_final": None if r[0].p_hat is None else r[0].p_hat[-1].tolist(),
                "p_true": None if r[0].p_true is None else r[0].p_true.tolist(),
                "limit_exceeded": r[0].limit_exceeded.tolist(),
                "limit_exceeded_at": r[0].first_exceeded_at,
            }
            for name, r in runs.items()
        },
        "table2": table.as_dict(),
        "table2_markdown": table.markdown(),
        "table2_csv": table.csv(),
        "animation": animation,
        "errata": [e._asdict() for e in items],
        "versions": _versions(),
    }


def _gains(result: SimulationResult) -> str:
    # The runner builds each controller from make_scenario's defaults; show those.
    from twolink_pin.controllers import AdaptiveFrictionGains, AdaptiveGains, PDGains, SlotineLiGains

    gains: Any = {
        "pd": PDGains(),
        "computed-torque": SlotineLiGains(),
        "robust": SlotineLiGains(),
        "adaptive": AdaptiveGains(),
        "adaptive-friction": AdaptiveFrictionGains(),
    }[result.controller]
    return ", ".join(f"{k} = {v}" for k, v in asdict(gains).items() if k != "lam")


def _model_facts(robot: RobotModel, samples: int = 1000) -> dict[str, Any]:
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
    links = []
    for j in range(1, robot.model.njoints):
        inertia = robot.model.inertias[j]
        links.append(
            {
                "joint": robot.model.names[j],
                "mass_kg": float(inertia.mass),
                "com_m": inertia.lever.tolist(),
                "Izz_com_kgm2": float(inertia.inertia[2, 2]),
            }
        )
    return {
        "urdf": str(robot.urdf_path),
        "link_lengths_m": robot.link_lengths.tolist(),
        "torque_limits_Nm": robot.torque_limits.tolist(),
        "payload_kg": robot.payload,
        "links": links,
        "p": dict(zip(robot.parameter_map.names, robot.p.tolist())),
        "closed_form_check": {"states": samples, "max_abs_dM": dev_m, "max_abs_dC": dev_c},
    }


def _table1(robot: RobotModel, via: ViaPoints) -> list[dict[str, Any]]:
    rows = []
    report_rows = list(errata.REPORT_TABLE1.values())
    for xy, report in zip(via.xy[:4], report_rows):
        ours = inverse_kinematics(robot, xy)
        rows.append({"xy": list(xy), "ours": ours.tolist(), "report": [list(r) for r in report]})
    return rows


def _torque_facts(check: TorqueCheck) -> dict[str, Any]:
    return {
        "peak_Nm": check.peak.tolist(),
        "peak_time_s": check.peak_time.tolist(),
        "limits_Nm": check.limits.tolist(),
        "margin_Nm": check.margin.tolist(),
        "within_limits": check.within_limits,
        "verdict": check.verdict(),
    }


def _versions() -> dict[str, str]:
    import importlib.metadata

    import pinocchio

    import twolink_pin

    return {
        "twolink_pin": twolink_pin.__version__,
        "pinocchio": pinocchio.__version__,
        "numpy": np.__version__,
        "matplotlib": importlib.metadata.version("matplotlib"),  # plotting.py is the only importer
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpus": str(os.cpu_count()),
    }


# -- pages ----------------------------------------------------------------------------------

CSS = """
body { font-family: system-ui, -apple-system, Segoe UI, Roboto, sans-serif; max-width: 1100px;
       margin: 0 auto; padding: 1rem 2rem; line-height: 1.45; color: #222; }
h1 { font-size: 1.7rem; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2rem; margin-top: 2.2rem; }
table { border-collapse: collapse; margin: .6rem 0 1rem; font-size: .92rem; }
th, td { border: 1px solid #ccc; padding: .25rem .55rem; text-align: right; }
th:first-child, td:first-child { text-align: left; }
thead th { background: #f2f4f7; }
figure { display: inline-block; margin: .4rem; vertical-align: top; }
figure img { max-width: 520px; width: 100%; border: 1px solid #ddd; }
figcaption { font-size: .85rem; color: #555; }
pre { background: #f6f8fa; padding: .6rem; overflow-x: auto; font-size: .85rem; }
.note { background: #fff8e1; border-left: 4px solid #f0b400; padding: .5rem .8rem; }
iframe { width: 100%; height: 560px; border: 1px solid #ccc; }
nav a { margin-right: .8rem; }
"""


def _esc(x: Any) -> str:
    return html.escape(str(x))


def _table(headers: list[str], rows: list[list[Any]], table_id: str = "") -> str:
    ident = f' id="{table_id}"' if table_id else ""
    head = "".join(f"<th>{_esc(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{_esc(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table{ident}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _figures(names: list[str]) -> str:
    return "".join(
        f'<figure><img src="figures/{_esc(n)}" alt="{_esc(n)}"><figcaption>{_esc(n)}</figcaption></figure>'
        for n in names
    )


def _g(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _write_pages(stage: Path, r: dict[str, Any]) -> None:
    md = _markdown(r)
    with atomic_write(stage / "report.md") as f:
        f.write(md)
    with atomic_write(stage / "table2.csv") as f:
        f.write(r["table2_csv"])
    write_json(
        stage / "results.json", {k: v for k, v in r.items() if k not in ("table2_markdown", "table2_csv")}
    )
    with atomic_write(stage / "index.html") as f:
        f.write(_html(r))


def _table2_headers(kind: str) -> list[str]:
    units = UNITS[kind]
    return ["controller", *(f"{c} [{units[i // 2]}]" for i, c in enumerate(COLUMNS))]


def _table2_rows(r: dict[str, Any], kind: str) -> list[list[str]]:
    rows = []
    for name, entry in r["controllers"].items():
        m = entry["metrics"][kind]
        rows.append([name, *(_g(x) for part in ("e", "edot", "tau") for x in m[part])])
    return rows


def _html(r: dict[str, Any]) -> str:
    m = r["model"]
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        "<title>twolink-pin: 2-link planar arm, reproduced</title>",
        f"<style>{CSS}</style></head><body>",
        "<h1>Kinematics, dynamics and control of a 2-link planar arm — reproduced with Pinocchio</h1>",
        "<p>Every number below was computed from <code>robots/twolink.urdf</code> by twolink-pin; the course "
        "report's values are shown beside ours, and the <a href='#errata'>errata</a> list where it is wrong.</p>",
        "<nav><a href='#model'>1 Model</a><a href='#kinematics'>2 Kinematics</a><a href='#trajectory'>3 Trajectory</a>"
        "<a href='#controllers'>4 Controllers</a><a href='#table2'>5 Table 2</a><a href='#animation'>6 Animation</a>"
        "<a href='#errata'>7 Errata</a><a href='#made'>8 How it was made</a></nav>",
        "<h2 id='model'>1. The model</h2>",
        f"<p>Link lengths L = {m['link_lengths_m']} m, motor limits {m['torque_limits_Nm']} N·m, "
        f"payload {m['payload_kg']} kg.</p>",
        _table(
            ["joint", "mass [kg]", "centre of mass [m]", "Izz about CoM [kg·m²]"],
            [
                [lk["joint"], _g(lk["mass_kg"], 8), _g(lk["com_m"][0], 4), _g(lk["Izz_com_kgm2"], 8)]
                for lk in m["links"]
            ],
            "model-inertias",
        ),
        "<p>Derived lumped parameters (p1 = Izz1 + m1 c1² + m2 L1² + p2, p2 = Izz2 + m2 c2², p3 = m2 L1 c2):</p>",
        _table(
            ["parameter", "from the URDF", "report"],
            [[k, _g(v, 12), {"p1": 3.4, "p2": 0.4, "p3": 0.3}.get(k, "")] for k, v in m["p"].items()],
            "model-p",
        ),
        f"<p>Closed-form check over {m['closed_form_check']['states']} random states: "
        f"max |M<sub>Pinocchio</sub> − M<sub>closed form</sub>| = {m['closed_form_check']['max_abs_dM']:.2e} kg·m², "
        f"max |ΔC| = {m['closed_form_check']['max_abs_dC']:.2e} kg·m²/s.</p>",
        "<h2 id='kinematics'>2. Kinematics: Table 1</h2>",
        _table(
            [
                "(x, y) [m]",
                "ours, q2 ≥ 0 [rad]",
                "report, first pair",
                "ours, q2 ≤ 0 [rad]",
                "report, second pair",
            ],
            [
                [
                    f"({row['xy'][0]:g}, {row['xy'][1]:g})",
                    "({:.4f}, {:.4f})".format(*row["ours"][0]),
                    "({:.4f}, {:.4f})".format(*row["report"][0]),
                    "({:.4f}, {:.4f})".format(*row["ours"][1]),
                    "({:.4f}, {:.4f})".format(*row["report"][1]),
                ]
                for row in r["table1"]
            ],
            "table1",
        ),
        "<h2 id='trajectory'>3. The trajectory</h2>",
        "<p>One 10th-order polynomial per joint through the via points at t = 0, 1, 2, 3, 4 s with zero velocity, "
        "acceleration and jerk at both ends, repeated every 4 s. Coefficients (ascending powers of t [s]):</p>",
        _table(
            ["k", "α_k ours", "α_k report", "β_k ours", "β_k report"],
            [
                [
                    k,
                    _g(r["trajectory"]["coefficients"][0][k], 6),
                    _g(r["trajectory"]["report_coefficients"][0][k], 4),
                    _g(r["trajectory"]["coefficients"][1][k], 6),
                    _g(r["trajectory"]["report_coefficients"][1][k], 4),
                ]
                for k in range(len(r["trajectory"]["coefficients"][0]))
            ],
            "coefficients",
        ),
        "<p class='note'>α₆ and β₄ differ (misprints), and the printed coefficients are rounded so much that the "
        "printed polynomials miss the via points badly beyond t ≈ 1 s — see <a href='#errata'>errata</a>.</p>",
        _figures(r["trajectory"]["figures"]),
        f"<p><b>Torque check.</b> {_esc(r['torque_check']['verdict'])}. Peaks {r['torque_check']['peak_Nm']} N·m at "
        f"t = {r['torque_check']['peak_time_s']} s; margins {r['torque_check']['margin_Nm']} N·m.</p>",
        "<h2 id='controllers'>4. The five controllers</h2>",
        f"<p>30-s runs, RK4 with dt = {r['simulation']['dt']} s (law at every stage), λ = {r['simulation']['lambda']} "
        f"1/s, q(0) = q<sub>d</sub>(0) + {list(r['simulation']['q0_offset'])} rad, q̇(0) = 0.</p>",
    ]
    for name, c in r["controllers"].items():
        mm = c["metrics"]
        parts += [
            f"<h3 id='ctrl-{_esc(name)}'>{_esc(name)}</h3>",
            f"<pre>{_esc(c['law'])}</pre>",
            f"<p>Gains: {_esc(c['gains'])}. Run time {c['seconds']:.1f} s.</p>",
            _table(
                ["norm", "e1 [rad]", "e2 [rad]", "ė1 [rad/s]", "ė2 [rad/s]", "τ1 [N·m]", "τ2 [N·m]"],
                [[k, *(_g(x) for part in ("e", "edot", "tau") for x in mm[k][part])] for k in ("rms", "max")],
            ),
            f"<p>max |e| over the last period: {[_g(x, 3) for x in mm['final_period_max_abs_e']]} rad.</p>",
        ]
        if c["p_hat_final"] is not None:
            parts.append(
                f"<p>p̂(30 s) = {[round(x, 4) for x in c['p_hat_final']]}, true {[round(x, 4) for x in c['p_true']]}.</p>"
            )
        if any(c["limit_exceeded"]):
            parts.append(
                f"<p class='note'>Commanded torque exceeded a motor limit: joints {c['limit_exceeded']}, first at "
                f"{c['limit_exceeded_at']} s (unsaturated plant, as in the report).</p>"
            )
        parts.append(_figures(c["figures"]))
    parts += [
        "<h2 id='table2'>5. Table 2</h2>",
        "<p>The report does not say which norm its Table 2 shows. Ours, in three defined norms over 30 s:</p>",
        "<h3>RMS = sqrt((1/T)∫x² dt)</h3>",
        _table(_table2_headers("rms"), _table2_rows(r, "rms"), "table2-rms"),
        "<h3>L2 = sqrt(∫x² dt)</h3>",
        _table(_table2_headers("l2"), _table2_rows(r, "l2"), "table2-l2"),
        "<h3>max |x|</h3>",
        _table(_table2_headers("max"), _table2_rows(r, "max"), "table2-max"),
        "<h3>The report's Table 2</h3>",
        _table(["controller", *COLUMNS], [[n, *v] for n, v in REPORT_TABLE2.items()], "table2-report"),
        f"<div class='note'>{_discussion(r)}</div>",
        "<h2 id='animation'>6. Animation</h2>",
    ]
    if r["animation"]:
        parts += [
            f"<p>The {ANIMATED_CONTROLLER} run in 3-D (arm, translucent desired 'ghost', trail and via points): "
            f"<a id='animation-link' href='{r['animation']}'>open the animation</a> (self-contained, works offline).</p>",
            f"<iframe id='animation-frame' src='{r['animation']}' title='animation' loading='lazy'></iframe>",
        ]
    else:
        parts.append("<p>Not generated (--no-animation).</p>")
    parts.append("<h2 id='errata'>7. Errata: where the report is wrong or silent</h2>")
    for e in r["errata"]:
        parts += [
            f"<h3>{_esc(e['topic'])}</h3>",
            f"<p><b>Report:</b> {_esc(e['report'])}<br><b>Correct / chosen:</b> {_esc(e['correct'])}</p>",
            f"<pre>{_esc(_evidence_text(e['evidence']))}</pre>",
        ]
    v = r["versions"]
    parts += [
        "<h2 id='made'>8. How it was made</h2>",
        _table(
            ["item", "value"],
            [[k, val] for k, val in v.items()]
            + [["command", r["command_line"]], ["total time", f"{r['total_seconds']:.1f} s"]],
            "made",
        ),
        "</body></html>",
    ]
    return "\n".join(parts)


def _evidence_text(evidence: dict[str, Any]) -> str:
    lines = []
    for k, val in evidence.items():
        if isinstance(val, float):
            val = f"{val:.6g}"
        elif isinstance(val, list):
            val = np.array2string(
                np.asarray(val, dtype=float), precision=5, suppress_small=False, max_line_width=100
            )
        lines.append(f"{k}: {val}")
    return "\n".join(lines)


def _discussion(r: dict[str, Any]) -> str:
    names = list(r["controllers"])
    ours = {n: r["controllers"][n]["metrics"]["rms"]["e"][0] for n in names}
    rep = {n: REPORT_TABLE2[n][0] for n in names}
    rank_ours = sorted(names, key=lambda n: ours[n])
    rank_rep = sorted(names, key=lambda n: rep[n])
    return (
        "<p><b>What is comparable.</b> The report's numbers depend on a norm, a λ and an initial state it never "
        "states, so magnitudes cannot be matched; rankings and qualitative behaviour can. "
        f"Ranking by joint-1 position error — ours (RMS): {' < '.join(rank_ours)}; report: {' < '.join(rank_rep)}.</p>"
        "<p><b>Agreement.</b> PD and computed torque converge to machine precision; the wrong-model ('robust') run "
        "keeps a periodic error that does not vanish; the adaptive runs reduce the error while their estimates drift "
        "slowly (see errata). <b>Differences.</b> With exact models PD and Slotine–Li both converge, so their ordering "
        "depends only on the transient, i.e. on the unstated λ and initial state; the report's large torque 'norms' "
        "(85–139 N·m for τ1) far exceed the ≈4 N·m the trajectory needs, which suggests an L2-type norm over the run "
        "dominated by the initial transient, not an RMS.</p>"
    )


def _markdown(r: dict[str, Any]) -> str:
    lines = [
        "# twolink-pin report",
        "",
        f"Generated by `{r['command_line']}` in {r['total_seconds']:.1f} s "
        f"(Pinocchio {r['versions']['pinocchio']}, numpy {r['versions']['numpy']}, Python {r['versions']['python']}).",
        "",
        "## Model",
        "",
        f"p = {r['model']['p']}; closed-form check max |ΔM| = {r['model']['closed_form_check']['max_abs_dM']:.2e}, "
        f"max |ΔC| = {r['model']['closed_form_check']['max_abs_dC']:.2e}.",
        "",
        "## Torque check",
        "",
        r["torque_check"]["verdict"],
        "",
        "## Table 2",
        "",
        r["table2_markdown"],
        "## Errata",
        "",
    ]
    for e in r["errata"]:
        lines += [
            f"### {e['topic']}",
            "",
            f"- Report: {e['report']}",
            f"- Correct: {e['correct']}",
            "",
            "```",
            _evidence_text(e["evidence"]),
            "```",
            "",
        ]
    return "\n".join(lines)


def terminal_progress(what: str, done: int, total: int) -> None:
    """Progress bar on stderr: ``[#####.....] 5/11 controller pd``."""
    width = 24
    filled = int(width * done / total)
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} {what:<32}")
    if done == total:
        sys.stderr.write("\n")
    sys.stderr.flush()
