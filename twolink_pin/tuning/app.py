"""The tuner: a Viser server whose page shows the arm, the controls, the plots and the
metrics of the latest run, and re-simulates (latest wins) whenever a control moves or,
with ``watch``, the law's file is saved. The page's parts live in their modules: the
controls (:mod:`.panel`), the results beside them (:mod:`.results`, :mod:`.table`,
:mod:`.plots`), the arm (:mod:`.scene`), the command and its files (:mod:`.command_folder`)."""

from __future__ import annotations

import atexit
import contextlib
import io
import os
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twolink_pin.errors import ControllerSpecError, InvalidParameterError, TwolinkPinError, raised_at
from twolink_pin.tuning.address import check_listen
from twolink_pin.tuning.knobs import choices_of, knob_changes, knobs_of, matrices_of
from twolink_pin.tuning.latest import STUCK_AFTER, LatestWins
from twolink_pin.tuning.periods import Cuts, heading
from twolink_pin.tuning.runner import Finished, Partial, PeriodDone, Request, Runner
from twolink_pin.tuning.scene import RESUME_AFTER
from twolink_pin.tuning.table import metrics_table

if TYPE_CHECKING:
    from twolink_pin.model import RobotModel
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.trajectory import Trajectory

WATCH_PERIOD = 0.25
"""How often the law's file is looked at [s] (``watch``)."""


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
        from twolink_pin.tuning.panel import Panel
        from twolink_pin.tuning.results import Results

        self.results = Results(self.server, self._keep_latest)
        self.status, self.metrics, self.plots = self.results.status, self.results.metrics, self.results.plots
        _, reference = self._runner.arm(payload)
        period = float(getattr(reference, "period", 0.0) or 0.0)
        matrices = matrices_of(type(controller).Gains, used)  # a full matrix keeps its off-diagonal terms
        choices = choices_of(type(controller).Gains, used)  # a gain that is a word: a dropdown
        self.panel = Panel(self.server, knobs, base, payload, self.changed, matrices, period, 10.0, choices)
        self._add_folders(robot)
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

    def _add_folders(self, robot: RobotModel) -> None:
        """The controls' folders below the run's: playback, and the run as a command with
        save and export."""
        from twolink_pin.tuning.command_folder import CommandFolder
        from twolink_pin.tuning.scene import ArmScene

        gui = self.server.gui
        with gui.add_folder("playback", expand_by_default=False, order=50.0):
            self.scene = ArmScene(self.server, robot, self.panel.channel)
        self.panel.focus.on_update(lambda _: self.scene.focused(str(self.panel.focus.value)))
        with gui.add_folder("as a command", order=60.0):
            self.files = CommandFolder(
                self.server,
                self.folder,
                lambda: self._latest,
                self._record_of,
                lambda p: self._runner.arm(p)[1],
            )

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
                self.metrics.content = metrics_table(done, cut, heading(k, part.periods, seconds))
                self.files.show(command)
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
            self.files.show(command)
            self.status.content = (
                f"run {generation}: {result.duration:g} s simulated in {done.seconds:.2f} s{suffix}"
            )
        self.scene.show(result.t, result.q, result.q_des)
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


__all__ = ["Tuner", "error_text", "run_line"]
