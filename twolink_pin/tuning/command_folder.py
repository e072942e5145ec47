"""The page's folder *as a command*: the ``twolink-pin simulate …`` line of the run shown
(every number as Python's ``repr`` prints it: the line's run is the run shown, bit for bit),
and the run written as files — *save run* (the ``.npz`` of ``simulate --save``) and *export
animation* (the HTML of ``animate --html``), each inside the tuner's folder
(:func:`~twolink_pin.tuning.outputs.page_path`) and offered as a download in the page that
asked."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twolink_pin.errors import TwolinkPinError
from twolink_pin.tuning.outputs import page_path

if TYPE_CHECKING:
    from twolink_pin.tuning.outcomes import Finished


class CommandFolder:
    """The folder's controls in the GUI's current container.

    Args:
        folder: Where the files are written (names inside it only).
        latest: The run shown (None before the first).
        record_of: ``(spec, payload)`` → what a saved run records (``simulate --save``).
        reference_of: ``payload`` → the run's reference (its via points are drawn).
    """

    def __init__(
        self,
        server: Any,
        folder: Path,
        latest: Callable[[], Finished | None],
        record_of: Callable[..., dict[str, Any]],
        reference_of: Callable[[float], Any],
    ) -> None:
        gui = server.gui
        self._server, self.folder = server, folder
        self._latest, self._record_of, self._reference_of = latest, record_of, reference_of
        self.command = gui.add_markdown("")
        hint = f"a file name inside {folder} (also offered as a download)"
        self.save_path = gui.add_text("run file (.npz)", "tune-run.npz", hint=hint)
        gui.add_button("save run").on_click(lambda event: self.save(event.client))
        self.html_path = gui.add_text("animation file (.html)", "tune-animation.html", hint=hint)
        gui.add_button("export animation").on_click(lambda event: self.export(event.client))
        self.saved = gui.add_markdown(f"files are written in `{folder}`")

    def show(self, command: str) -> None:
        """The command line of the run shown."""
        self.command.content = f"```\n{command}\n```"

    def _offer(self, client: Any, path: Path) -> None:
        """Offer the file just written as a download in the page of ``client`` (None: every page)."""
        target = client if client is not None else self._server
        target.send_file_download(path.name, path.read_bytes())

    def save(self, client: Any = None) -> None:
        """*save run*: the run shown as ``simulate --save`` writes it."""
        from twolink_pin.simulation.storage import save_result

        done = self._latest()
        if done is None:
            return
        try:
            path = page_path(self.folder, str(self.save_path.value), ".npz", "run file")
            save_result(done.result, path, record=self._record_of(*done.request[:2]))
            self._offer(client, path)
            self.saved.content = f"saved `{path}` (and offered as a download)"
        except (TwolinkPinError, OSError) as exc:
            self.saved.content = f"**not saved**: {exc}"

    def export(self, client: Any = None) -> None:
        """*export animation*: the run shown as ``animate --html`` writes it."""
        from twolink_pin.kinematics import joint_positions
        from twolink_pin.visualization import write_html
        from twolink_pin.visualization.overlays import run_overlays

        done = self._latest()
        if done is None:
            return
        result = done.result
        via_q = getattr(self._reference_of(done.request.payload), "via_q", None)
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
                **run_overlays(done.request.spec.plant.wrench, result.t),
            )
            self._offer(client, path)
            self.saved.content = f"animation written to `{path}` (and offered as a download)"
        except (TwolinkPinError, OSError) as exc:
            self.saved.content = f"**not written**: {exc}"


__all__ = ["CommandFolder"]
