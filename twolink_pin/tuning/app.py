"""The tuner: a Viser server whose page shows the arm, the controls, the plots and the
metrics of the latest run, and re-simulates (latest wins) whenever a control moves or,
with ``watch``, the law's file is saved."""

from __future__ import annotations

import atexit
import contextlib
import io
import os
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.errors import ControllerSpecError, InvalidParameterError, TwolinkPinError, raised_at
from twolink_pin.tuning.address import check_listen
from twolink_pin.tuning.knobs import knob_changes, knobs_of, matrices_of
from twolink_pin.tuning.latest import STUCK_AFTER, LatestWins
from twolink_pin.tuning.outputs import page_path
from twolink_pin.tuning.periods import Cuts, heading
from twolink_pin.tuning.runner import Finished, Partial, PeriodDone, Request, Runner
from twolink_pin.tuning.scene import RESUME_AFTER

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.trajectory import Trajectory

WATCH_PERIOD = 0.25
"""How often the law's file is looked at [s] (``watch``)."""


WIDE = 3
"""A run with more joints than this shows, per metric, its largest joint (the panel is narrow)."""


def metrics_table(this: Finished, columns: Mapping[str, Finished | None]) -> str:
    """The metrics of this run beside other runs (column name → run; None: "–"), as
    Markdown. Up to :data:`WIDE` joints a cell lists every joint; beyond, the largest
    joint's value and which joint (``0.012 (j4)``): 6 or 7 joints fit the panel."""
    runs = {"this run": this, **columns}

    def cell(done: Finished | None, pick: Callable[[Finished], Any]) -> str:
        if done is None:
            return "–"
        value = np.asarray(pick(done), dtype=float)
        if value.ndim == 0:
            return f"{float(value):.3g}"
        if value.size <= WIDE:
            return ", ".join(f"{x:.3g}" for x in value)
        j = int(np.nanargmax(np.abs(value)))
        return f"{value[j]:.3g} (j{j + 1})"

    def m(kind: str, name: str) -> Callable[[Finished], Any]:
        return lambda d: getattr(getattr(d.metrics, kind), name)

    rows = [
        ("RMS e [rad]", m("rms", "e")),
        ("max \\|e\\| [rad]", m("max", "e")),
        ("last period max \\|e\\| [rad]", lambda d: d.metrics.final_period_max_abs_e),
        ("RMS τ [N·m]", m("rms", "tau")),
        ("max \\|τ\\| [N·m]", m("max", "tau")),
    ]
    if this.task is not None:
        rows += [
            ("task RMS \\|p − p_d\\| [mm]", lambda d: d.task.position_rms_mm if d.task else float("nan")),
            ("task RMS angle [deg]", lambda d: d.task.orientation_rms_deg if d.task else float("nan")),
        ]
    lines = ["| | " + " | ".join(runs) + " |", "|---" * (len(runs) + 1) + "|"]
    lines += [f"| {name} | " + " | ".join(cell(run, f) for run in runs.values()) + " |" for name, f in rows]
    if this.result.q.shape[1] > WIDE:
        lines.append("\n(largest joint shown: `tune --json` prints every joint)")
    return "\n".join(lines)


def run_line(done: Finished, command: str, generation: int) -> dict[str, Any]:
    """What the tuner reports of a finished run (``tune --json`` prints it as one line):
    ``gains`` and ``metrics`` as ``simulate --json`` prints them, the reproducing
    ``command``, the plant and its settings."""
    line: dict[str, Any] = {
        "run": generation,
        "controller": done.result.controller,
        "gains": done.gains,
        "metrics": done.metrics.as_dict(),
        "command": command,
        "plant": done.plant,
        "payload": done.request.payload,
        "spec": done.request.spec.as_dict(),
        "seconds": done.seconds,
    }
    if done.task is not None:
        line["task_metrics"] = done.task.as_dict()
    return line


def error_text(exc: BaseException) -> str:
    """A failed run in one line; a law file that did not load: with the file and line (its
    message names the user's file and line, :func:`~twolink_pin.user_code.guarded`: never
    importlib's frames)."""
    text = str(exc)
    cause = exc.__context__ or exc.__cause__
    if cause is not None and not isinstance(exc, (InvalidParameterError, ControllerSpecError)):
        where = raised_at(cause)
        if where and where.strip(" ()") not in text:
            text += where
    return text


def _stop_quietly(server: Any) -> None:
    """Stop a Viser server without its "(viser) Server stopped" line on stdout (printed by its
    thread as it ends: stdout is redirected until that thread has ended)."""
    thread = getattr(getattr(server, "_websock_server", None), "_server_thread", None)
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()
        if isinstance(thread, threading.Thread):
            thread.join(10.0)


class Tuner:
    """The tuner's server and its state.

    Args:
        base: The run the command line describes (the controls start there).
        payload: Its payload [kg].
        arm: ``payload`` → the robot and the reference (loaded as the command line says).
        command_of: ``(spec, payload)`` → the ``twolink-pin simulate …`` line of that run.
        record_of: ``(spec, payload)`` → what a saved run records (``simulate --save``).
        report: Called with each run's line (:func:`run_line`) or a failure's
            (``{"error": ..., "command": ...}``), on the worker thread.
        host, port: Where the page is served (port 0: a free one): checked first
            (:func:`~twolink_pin.tuning.address.check_listen`).
        watch: Re-read the law's file when it changes.
        folder: Where the page's "run file" and "animation file" boxes write (names inside it
            only, :func:`~twolink_pin.tuning.outputs.page_path`); default: the working directory.
        limit: A run that simulates no block of samples for this long is left behind and
            shown as failed [s] (None: no limit).
        stuck_after: A superseded run that has not stopped this long after the change is left
            behind [s] (:class:`~twolink_pin.tuning.latest.LatestWins`).
    """

    def __init__(
        self,
        base: RunSpec,
        payload: float,
        arm: Callable[[float], tuple[RobotModel, Trajectory]],
        command_of: Callable[[RunSpec, float], str],
        record_of: Callable[[RunSpec, float], dict[str, Any]],
        report: Callable[[dict[str, Any]], None],
        host: str = "127.0.0.1",
        port: int = 0,
        watch: bool = False,
        folder: Path | None = None,
        limit: float | None = None,
        stuck_after: float = STUCK_AFTER,
    ) -> None:
        from twolink_pin.run_spec import gains_used

        self._command_of, self._record_of, self._report = command_of, record_of, report
        self.folder = (folder or Path.cwd()).resolve()
        self.address = check_listen(host, port)  # a refused host or port: exit 2 before serving
        self._limit = limit
        self._runner = Runner(
            arm,
            lambda: self._session.superseded(),
            self._partial,
            alive=lambda: self._session.alive(),
            period_done=self._period,
        )
        self._shown = threading.Lock()  # a run's period is shown only while that run is the newest
        self._cuts = Cuts()
        robot, _ = self._runner.arm(payload)
        controller = base.build(robot, base.read_parameters(robot)).controller  # a refused value: exit 2 here
        used = gains_used(controller)
        knobs = knobs_of(type(controller).Gains, used)
        self._knobs = knobs
        self._law, self._default_gains = base.law, used
        self.server = self._start_server(host, port)
        self.server.gui.configure_theme(control_width="large")
        gui = self.server.gui
        gui.add_markdown(
            f"**twolink-pin tune** · {controller.title} (`{controller.name}`) on {robot.name}", order=0.0
        )
        self.status = gui.add_markdown("starting…", order=1.0)
        from twolink_pin.tuning.panel import Panel

        _, reference = self._runner.arm(payload)
        period = float(getattr(reference, "period", 0.0) or 0.0)
        matrices = matrices_of(type(controller).Gains, used)  # a full matrix keeps its off-diagonal terms
        self.panel = Panel(self.server, knobs, base, payload, self.changed, matrices, period, order=10.0)
        self._add_results(robot)
        self._lock = threading.Lock()
        self._latest: Finished | None = None
        self._previous: Finished | None = None
        self._defaults: Finished | None = None
        self._kept: tuple[str, Finished] | None = None
        self._law_version = 0
        self._knobs_version = 0  # the law version the controls were last checked against
        self._base = base
        self._closed = threading.Event()
        self._session: LatestWins[Request, Finished] = LatestWins(
            self._runner, self._deliver, stuck_after=stuck_after, limit=limit, on_abandoned=self._abandoned
        )
        self._watcher = None
        law = base.law if isinstance(base.law, str) else ""
        if watch and ".py:" in law:
            self._watcher = threading.Thread(
                target=self._watch,
                args=(Path(law.rpartition(":")[0]),),
                name="twolink-pin-tune-watch",
                daemon=True,
            )
            self._watcher.start()
        self.changed()

    def _add_results(self, robot: RobotModel) -> None:
        """The page's folders below the controls: metrics (with "keep this run"), plots,
        playback, and the run as a command with save and export."""
        from twolink_pin.tuning.plots import Plots
        from twolink_pin.tuning.scene import ArmScene

        gui = self.server.gui
        with gui.add_folder("metrics", order=20.0):
            self.metrics = gui.add_markdown("")
            self.keep = gui.add_button(
                "keep this run",
                hint="pin the run shown as a reference: a column here, grey curves in the plots",
            )
            self.keep.on_click(lambda _: self._keep_latest())
        with gui.add_folder("plots", order=30.0) as folder:
            self.plots = Plots(self.server, folder)
        with gui.add_folder("playback", order=50.0):
            self.scene = ArmScene(self.server, robot)
        with gui.add_folder("as a command", order=60.0):
            self.command = gui.add_markdown("")
            hint = f"a file name inside {self.folder} (also offered as a download)"
            self.save_path = gui.add_text("run file (.npz)", "tune-run.npz", hint=hint)
            gui.add_button("save run").on_click(lambda event: self._save(event.client))
            self.html_path = gui.add_text("animation file (.html)", "tune-animation.html", hint=hint)
            gui.add_button("export animation").on_click(lambda event: self._export(event.client))
            self.saved = gui.add_markdown(f"files are written in `{self.folder}`")

    def _start_server(self, host: str, port: int) -> Any:
        """The Viser server on ``host``:``port``, stopped quietly at exit."""
        import viser

        with contextlib.redirect_stdout(io.StringIO()):  # its banner: the command prints the URL itself
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self._stopped = False
        websock = getattr(self.server, "_websock_server", None)
        if websock is not None:  # at exit (an error or a signal while the page is built): quietly
            atexit.unregister(websock.stop)
        atexit.register(self._stop_server)
        if port and self.server.get_port() != port:  # taken since the check
            self._stop_server()
            raise InvalidParameterError("--port", port, f"a free port on {host} (it is in use)")
        return self.server

    @property
    def url(self) -> str:
        """The page's address."""
        host = str(self.server.get_host())
        return f"http://{f'[{host}]' if ':' in host else host}:{self.server.get_port()}/"

    @property
    def session(self) -> LatestWins[Request, Finished]:
        """The runs (latest wins): how many started, how many were cancelled."""
        return self._session

    def changed(self) -> None:
        """Re-run with the controls' values (superseding a run in flight)."""
        try:
            spec, payload = self.panel.spec()
        except TwolinkPinError as exc:
            self.panel.show_error(None, str(exc))
            return
        bound = f" (given up after {self._limit:g} s without progress: --timeout)" if self._limit else ""
        self.status.content = f"running…{bound}"
        self.scene.hold(True)  # the page's time goes to the controls and the new run, not the playback
        with self._shown:  # after this, no period of an older run is shown
            self._session.submit(Request(spec, payload, self._law_version))

    def close(self) -> None:
        """Stop the runs, the playback and the server (quietly: no line of Viser's)."""
        self._closed.set()
        self._session.close()
        self.scene.close()
        self._stop_server()

    def _stop_server(self) -> None:
        """Stop the server once, quietly (also at exit if :meth:`close` was never reached)."""
        atexit.unregister(self._stop_server)
        if not self._stopped:
            self._stopped = True
            _stop_quietly(self.server)

    def _abandoned(self, generation: int, seconds: float) -> None:
        """A run left behind (a law that does not return): say so in the page, now and beside
        the next run shown."""
        self._left_behind = (
            f"**run {generation} cannot be stopped**: the law's compute had not returned after {seconds:.1f} s; "
            "it was left running in the background"
        )
        self.status.content = self._left_behind

    _left_behind = ""
    _period_shown: tuple[int, str] = (0, "")  # the run whose period is shown, and its status line

    def _partial(self, part: Partial) -> None:
        """Show the part of the run in flight simulated so far (on the worker thread); once a
        period of it is shown, only how far it got (the period's table and plots stay)."""
        if self._session.superseded():
            return
        progress = f"running… {part.t[-1]:.3g} of {part.duration:g} s simulated"
        shown = self._period_shown
        if shown[0] == self._session.generation:
            self.status.content = f"{shown[1]}; {progress}"
            return
        step = max(1, len(part.t) // 600)  # the final run redraws at full resolution
        self.scene.show(part.t[::step], part.q[::step], part.q_des[::step])
        self.plots.show_partial(part)
        self.status.content = progress

    def _period(self, part: PeriodDone) -> None:
        """Show the run in flight up to the end of its period k (worker thread): its metrics
        beside the other runs' cut to k periods, the plots over ``0 … k T``; the scene keeps
        the last finished run. Never a superseded run's (the lock :meth:`changed` submits under)."""
        done, k, seconds = part.done, part.k, part.done.result.duration
        with self._lock:
            columns: dict[str, Finished | None] = {
                "previous": self._latest,
                "defaults": self._defaults or done,
            }
            columns.update([self._kept] if self._kept is not None else [])
        cut = {name: run if run is done else self._cuts(run, k) for name, run in columns.items()}
        command = self._command_of(done.request.spec, done.request.payload)  # the run whose start is shown
        with self._shown:
            if self._session.superseded():
                return
            generation = self._session.generation
            line = f"run {generation}: period {k} of {part.periods} shown ({seconds:g} s simulated in {done.seconds:.2f} s)"
            self.plots.show(done, columns)  # the others resampled on this run's times: 0 … k T
            with self.server.atomic():
                self.metrics.content = heading(k, part.periods, seconds) + metrics_table(done, cut)
                self.command.content = f"```\n{command}\n```"
                self.status.content = f"{line}; running…"
            self._period_shown = (generation, line)

    def _deliver(self, generation: int, request: Request, outcome: Finished | Exception) -> None:
        command = self._command_of(request.spec, request.payload)
        if isinstance(outcome, Exception):
            text = error_text(outcome)
            gain = getattr(outcome, "name", None)
            gain = gain.partition("[")[0] if isinstance(gain, str) else None
            if isinstance(outcome, InvalidParameterError) and gain in self.panel.gain_errors:
                self.panel.show_error(gain, text)
            else:
                self.panel.show_error(None, "")
            kept = self._check_controls(request) if request.law_version != self._knobs_version else ""
            self.status.content = (
                f"**run {generation} failed** (the last good run stays on screen): {text}{kept}"
            )
            self.scene.hold(False, RESUME_AFTER)
            self._report({"run": generation, "error": text, "command": command})
            return
        self.panel.show_error(None, "")
        kept = self._check_controls(request) if request.law_version != self._knobs_version else ""
        with self._lock:
            self._previous, self._latest = self._latest, outcome
            if self._defaults is None:
                self._defaults = outcome
            previous, defaults = self._previous, self._defaults
        left, self._left_behind = self._left_behind, ""
        self._show(outcome, previous, defaults, command, generation, kept + (f" · {left}" if left else ""))
        self._report(run_line(outcome, command, generation))

    def _show(
        self,
        done: Finished,
        previous: Finished | None,
        defaults: Finished | None,
        command: str,
        generation: int,
        suffix: str = "",
    ) -> None:
        result = done.result
        kept = self._kept
        columns: dict[str, Finished | None] = {"previous": previous, "defaults": defaults}
        if kept is not None:
            columns[kept[0]] = kept[1]
        self.plots.show(done, columns)  # first: the status line below says all is shown
        with self.server.atomic():
            self.metrics.content = metrics_table(done, columns)
            self.command.content = f"```\n{command}\n```"
            self.status.content = (
                f"run {generation}: {result.duration:g} s simulated in {done.seconds:.2f} s{suffix}"
            )
        force = None if result.wrench is None else -np.asarray(result.wrench)[:, :3]  # on the arm
        self.scene.show(result.t, result.q, result.q_des, done.request.spec.plant.scene, force)
        self.scene.hold(False, RESUME_AFTER)

    def _keep_latest(self) -> None:
        """Pin the run shown as a reference, named as ``compare`` names a variant."""
        from twolink_pin.law_variant import format_variant

        with self._lock:
            done, previous, defaults = self._latest, self._previous, self._defaults
        if done is None:
            return
        law = self._law if isinstance(self._law, str) else done.result.controller
        try:
            name = format_variant(law, done.gains, defaults=self._default_gains)
        except TwolinkPinError:
            name = f"kept run ({law})"
        self._kept = (name, done)
        self._show(done, previous, defaults, self._command_of(done.request.spec, done.request.payload), 0)
        self.status.content = f"kept `{name}` as a reference"

    def _check_controls(self, request: Request) -> str:
        """After ``--watch`` reloaded the law: whether its ``Gains`` declaration still gives the
        page's controls; if not, the page keeps them and the status says what changed."""
        from twolink_pin.run_spec import gains_used

        base = self._base
        try:
            robot, _ = self._runner.arm(request.payload)
            controller = base.build(robot, base.read_parameters(robot)).controller
        except TwolinkPinError:  # the file does not load: the run's own error says so
            return ""
        self._knobs_version = request.law_version
        changes = knob_changes(self._knobs, knobs_of(type(controller).Gains, gains_used(controller)))
        if not changes:
            return ""
        return (
            f" · **the law's Gains changed** ({'; '.join(changes)}): the page kept its old controls (the run and "
            "its command line use their values); restart tune for the new ones"
        )

    def _offer(self, client: Any, path: Path) -> None:
        """Offer the file just written as a download in the page of ``client`` (None: every page)."""
        target = client if client is not None else self.server
        target.send_file_download(path.name, path.read_bytes())

    def _save(self, client: Any = None) -> None:
        from twolink_pin.simulation.storage import save_result

        done = self._latest
        if done is None:
            return
        try:
            path = page_path(self.folder, str(self.save_path.value), ".npz", "run file")
            save_result(done.result, path, record=self._record_of(*done.request[:2]))
            self._offer(client, path)
            self.saved.content = f"saved `{path}` (and offered as a download)"
        except (TwolinkPinError, OSError) as exc:
            self.saved.content = f"**not saved**: {exc}"

    def _export(self, client: Any = None) -> None:
        from twolink_pin.kinematics import joint_positions
        from twolink_pin.visualization import write_html
        from twolink_pin.visualization.overlays import run_overlays

        done = self._latest
        if done is None:
            return
        result = done.result
        _, reference = self._runner.arm(done.request.payload)
        via_q = getattr(reference, "via_q", None)
        points = None if via_q is None else joint_positions(done.robot, via_q)[:, -1, :]
        try:
            path = page_path(self.folder, str(self.html_path.value), ".html", "animation file")
            write_html(
                done.robot,
                result.t,
                result.q,
                result.q_des,
                path=path,
                via_points=points,
                **run_overlays(
                    done.request.spec.plant.wrench, result.t, done.request.spec.plant.scene, result.wrench
                ),
            )
            self._offer(client, path)
            self.saved.content = f"animation written to `{path}` (and offered as a download)"
        except (TwolinkPinError, OSError) as exc:
            self.saved.content = f"**not written**: {exc}"

    def _watch(self, path: Path) -> None:
        def stamp() -> tuple[int, int] | None:
            try:
                info = os.stat(path)
            except OSError:
                return None
            return info.st_mtime_ns, info.st_size

        seen = stamp()
        while not self._closed.wait(WATCH_PERIOD):
            now = stamp()
            if now != seen and now is not None:
                seen = now
                self._law_version += 1
                self.status.content = f"`{path}` changed: reloading the law"
                self.changed()


__all__ = ["Tuner", "error_text", "metrics_table", "run_line"]
