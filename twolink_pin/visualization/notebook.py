"""The animated scene inside a Jupyter notebook's output: :func:`inline_animation`.

The notebook shows the same self-contained page as :func:`~twolink_pin.visualization.write_html`
in an ``<iframe srcdoc="…">``: the whole page (meshcat's viewer, three.js and every scene
command) is the attribute's value, HTML-escaped, so it plays in the saved notebook, in a
notebook rendered to HTML, and on the documentation site, with no server and no network
request. Jupyter displays any object with a ``_repr_html_`` method, so this module does
not import IPython.
"""

from __future__ import annotations

import html

import numpy.typing as npt

from twolink_pin.contact.scene import Scene
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.visualization.html import scene_page


class InlineAnimation:
    """An animated scene that a notebook displays inline (``_repr_html_``).

    Made by :func:`inline_animation`. In the viewer, *Open Controls → Animations* plays,
    pauses and scrubs the motion.
    """

    def __init__(self, page: str, height: int) -> None:
        self.page = page
        """The self-contained HTML page the frame shows (:func:`~twolink_pin.visualization.html.scene_page`)."""
        self.height = height
        """Height of the frame [px]; its width follows the notebook's."""

    def _repr_html_(self) -> str:
        """An ``<iframe>`` whose ``srcdoc`` is the page; scripts only, no access to the notebook."""
        return (
            f'<iframe class="twolink-pin-animation" title="arm motion (meshcat)" sandbox="allow-scripts" '
            f'style="width: 100%; height: {self.height}px; border: 1px solid #ddd" '
            f'srcdoc="{html.escape(self.page, quote=True)}"></iframe>'
        )

    def __repr__(self) -> str:
        return f"InlineAnimation(height={self.height}, page={len(self.page)} characters)"


def inline_animation(
    robot: RobotModel,
    t: npt.ArrayLike,
    q: npt.ArrayLike,
    q_des: npt.ArrayLike | None = None,
    *,
    via_points: npt.ArrayLike | None = None,
    fps: float = 25.0,
    loop: bool = False,
    height: int = 420,
    wrench: npt.ArrayLike | None = None,
    wrench_frame: str | None = None,
    desired_frame: bool | npt.ArrayLike = False,
    surfaces: Scene | None = None,
) -> InlineAnimation:
    """The animated scene of a run, for display in a notebook cell.

    The last expression of a cell (or ``IPython.display.display(...)``) shows it. The
    frame holds the page :func:`~twolink_pin.visualization.write_html` would write: arm,
    translucent desired ghost, end-effector trail, desired path and via points. An 8-s run
    at 25 fps is about 1.2 MB of notebook output.

    Args:
        robot: The arm.
        t: Sample times [s], shape (N,), N >= 2, strictly increasing.
        q: Joint angles of the arm [rad], shape (N, nq).
        q_des: Desired joint angles [rad], shape (N, nq), drawn as the ghost; or ``None``.
        via_points: End-effector via points [m], shape (M, 3) or (M, 2); or ``None``.
        fps: Animation frames per second of motion [1/s], > 0.
        loop: Repeat the animation forever.
        height: Height of the frame in the notebook [px], 100 to 2000.
        wrench, wrench_frame, desired_frame, surfaces: the force arrow, the desired frame's
            triad and a scene's surfaces, as :func:`~twolink_pin.visualization.write_html`.

    Returns:
        The animation; its ``_repr_html_`` is the ``<iframe srcdoc=…>``.

    Raises:
        InvalidParameterError: as :func:`~twolink_pin.visualization.write_html`, or a
            ``height`` outside 100–2000 px.
        InvalidURDFError: a mesh of the robot's URDF cannot be found or loaded.
    """
    if not (isinstance(height, int) and not isinstance(height, bool) and 100 <= height <= 2000):
        raise InvalidParameterError("height", height, "a whole number of pixels from 100 to 2000")
    page = scene_page(
        robot,
        t,
        q,
        q_des,
        via_points=via_points,
        fps=fps,
        loop=loop,
        title="arm motion",
        wrench=wrench,
        wrench_frame=wrench_frame,
        desired_frame=desired_frame,
        surfaces=surfaces,
    )
    return InlineAnimation(page, height)
