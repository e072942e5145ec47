"""``sweep``: a Monte Carlo study of one law, in-process or on Dask."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from twolink_pin.cli.commands.common import (
    gain_values,
    gains_echo,
    robot_from_args,
    run_spec,
    trajectory_from_args,
)
from twolink_pin.cli.output import emit, progress_bar

if TYPE_CHECKING:
    from twolink_pin.studies.sweep import SweepOutput


def cmd_sweep(args: argparse.Namespace) -> int:
    from twolink_pin.studies import cluster
    from twolink_pin.studies.sweep import SweepConfig, run_sweep

    if (args.workers is not None or args.scheduler is not None) and not cluster.available():
        option = "--workers" if args.workers is not None else "--scheduler"
        print(
            f"twolink-pin: error: {option} needs Dask, which is not installed: {cluster.INSTALL_HINT}",
            file=sys.stderr,
        )
        return 1
    robot = robot_from_args(args)
    trajectory = trajectory_from_args(args, robot)
    fixed = [g for g in args.gain if isinstance(g, str)]  # NAME=WORD: one value for every run
    run = run_spec(args, args.controller, fixed_gains=False)
    if fixed:
        run = replace(run, gains=tuple(gain_values(fixed).items()))
    config = SweepConfig(
        run=run,
        samples=args.samples,
        seed=args.seed,
        q0_spread=args.q0_spread,
        param_error=args.param_error,
        gains=tuple(g for g in args.gain if not isinstance(g, str)),
        wrench_scale=args.wrench_scale,
        chunk=args.chunk,
        threads=args.threads,
    )
    config.run.check_effective(robot, trajectory=trajectory)
    bars: list[Any] = []  # shown from the first runs on: its rate and ETA leave out a cluster's start

    def progress(done: int, total: int) -> None:
        if not bars:
            bars.append(progress_bar(config.samples, "run", f"sweep {args.controller}"))
        bars[0].update(done - bars[0].n)

    def notify(line: str) -> None:
        if bars:
            bars[0].write(line, file=sys.stderr)
        else:
            print(line, file=sys.stderr, flush=True)

    try:
        output = run_sweep(
            config,
            robot,
            trajectory,
            args.out,
            progress=progress,
            keep_trajectories=args.keep_trajectories,
            plot=not args.no_plot,
            scheduler=args.scheduler,
            workers=args.workers,
            timeout=args.connect_timeout,
            notify=notify,
        )
    finally:
        if bars:
            bars[0].close()
    summary = output.summary
    gains, gains_text = gains_echo(config.run.build(robot).controller)  # the nominal law's
    drawn = {g.name: [g.low, g.high] for g in config.gains}
    if args.json:
        payload = {
            **summary,
            "gains_used": gains,  # the nominal law's; "gains" (the summary's) are the drawn ranges
            "files": [str(f) for f in output.files],
            "seconds": output.seconds,
        }
        emit(args, {**payload, "engine": output.engine, "chunk": output.chunk}, "")
        return 0
    emit(args, {}, "\n".join(_sweep_lines(summary, output, gains_text, drawn)))
    return 0


def _sweep_lines(
    summary: dict[str, Any], output: SweepOutput, gains_text: str, drawn: dict[str, list[float]]
) -> list[str]:
    """``sweep``'s text: the counts, where it ran, the gains (nominal and ``drawn`` ranges), the
    percentiles of every metric and the files written."""
    lines = [
        f"sweep {summary['controller']} on {summary['robot']}: {summary['runs']} runs in {output.seconds:.1f} s "
        f"({summary['diverged']} diverged, {summary['limit_exceeded']} exceeded a torque limit, "
        f"{summary['position_crossed']} crossed a position range, {summary['velocity_crossed']} a velocity limit)",
        f"  ran {'' if output.engine == 'in-process' else 'on '}{output.engine}, in chunks of {output.chunk} runs",
        f"  gains {gains_text}"
        + "".join(f"; {name} drawn per run from U({lo:g}, {hi:g})" for name, (lo, hi) in drawn.items()),
    ]
    width = max([28, *(len(name) for name in summary["metrics"] if len(name) <= 40)])  # long names overflow
    lines.append(f"  {'metric':{width}s} {'p5':>12s} {'median':>12s} {'p95':>12s}")
    for name, stat in summary["metrics"].items():
        cells = ["—" if stat[k] is None else f"{stat[k]:.5g}" for k in ("p5", "median", "p95")]
        lines.append(f"  {name:{width}s} {cells[0]:>12s} {cells[1]:>12s} {cells[2]:>12s}")
    if "note" in summary:
        lines.append(f"  {summary['note']}")
    lines += [f"  wrote {f}" for f in output.files]
    return lines
