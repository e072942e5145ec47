"""The tuner's controls in Viser's GUI and the :class:`~twolink_pin.run_spec.RunSpec` they
describe: the law's gains (:mod:`.gain_controls`), the run (periods, duration) and the plant
(:mod:`.plant_controls`), each in its folder. Each control is labelled with the gain's name
as ``twolink-pin controllers`` prints it and its unit; a slider moves with the arrow keys on
its grid (:mod:`.steps`); every box that takes numbers runs what is typed on Enter or when it
loses focus (:mod:`.typed_js`, :mod:`.typed`), and a refused value is named next to its
control. ``periods`` sets the duration to a whole number of the reference's periods."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.gain_controls import GainControls
from twolink_pin.tuning.knobs import Knob
from twolink_pin.tuning.plant_controls import PlantControls
from twolink_pin.tuning.typed import Channel, read_number
from twolink_pin.tuning.typed_js import CHANNEL_LABEL, FOCUS_LABEL, typed_html

if TYPE_CHECKING:
    from twolink_pin.run_spec import RunSpec

MAX_PERIODS = 20
"""Most periods the periods control offers (more when the command line asks for more)."""
MAX_DURATION = 60.0
"""Longest run the duration control offers [s] (more when the command line asks for more)."""


class Panel:
    """The controls of ``knobs`` and of the run settings of ``base`` in ``server``'s GUI;
    ``changed()`` is called when the user moves one.

    Args:
        matrices: The full value ``(k, k)`` of each matrix gain (:func:`~.knobs.matrices_of`):
            its off-diagonal terms run with the diagonal the sliders set.
        choices: Each gain that is a word: its words and the word it starts at
            (:func:`~.knobs.choices_of`).
        period: The reference's period [s] (the periods control's unit).
        order: Where the gains' folder sits in the page (Viser's ``order``); the run's
            settings sit at ``order + 10``, the plant's at ``order + 11``.
    """

    def __init__(
        self,
        server: Any,
        knobs: list[Knob],
        base: RunSpec,
        payload: float,
        changed: Callable[[], None],
        matrices: dict[str, np.ndarray] | None = None,
        period: float | None = None,
        order: float = 10.0,
        choices: dict[str, tuple[tuple[str, ...], str]] | None = None,
    ) -> None:
        self._base = base
        self._changed = changed
        self._period = period if period and math.isfinite(period) and period > 0 else None
        gui = server.gui
        gui.add_html(typed_html(), order=order - 0.5)
        self.channel = Channel()
        self.channel.attach(gui.add_text(CHANNEL_LABEL, "", order=order - 0.4))
        self.focus = gui.add_text(FOCUS_LABEL, "0", order=order - 0.3)
        """Holds ``1`` while a control has the focus (the page's script sets it)."""
        with gui.add_folder("gains", order=order):
            self._gains = GainControls(gui, knobs, changed, matrices, self.channel, choices)
        self.sliders = self._gains.sliders
        self.typed = self._gains.typed
        self.gain_errors = self._gains.errors
        self._add_run_controls(gui, base, order + 10)
        with gui.add_folder("plant", expand_by_default=False, order=order + 11):
            self.plant = PlantControls(
                gui,
                base.plant,
                payload,
                base.simulation.duration,
                self.channel,
                changed,
            )

    def _add_run_controls(self, gui: Any, base: RunSpec, order: float) -> None:
        """The run's length: periods of the reference and the duration, in a folder at ``order``."""
        sim = base.simulation
        self.periods: Any = None
        with gui.add_folder("run", order=order):
            if self._period:
                count = max(1, round(sim.duration / self._period))
                self.periods = gui.add_slider(
                    "periods",
                    1,
                    max(MAX_PERIODS, count),
                    1,
                    count,
                    hint=f"the run's duration in periods of the reference ({self._period:g} s each)",
                )
                self.periods.on_update(self._periods_moved)
                self.channel.register("periods", lambda _i, text: self._typed_periods(text))
            self.duration = gui.add_number(  # bounded: a run in flight is not interrupted
                "duration [s]", sim.duration, min=sim.dt, max=max(MAX_DURATION, sim.duration), step=0.1
            )
            self.duration.on_update(self._duration_moved)
            self.channel.register("duration [s]", lambda _i, text: self._typed_duration(text))
            self.run_error = gui.add_markdown("")

    def _duration_moved(self, event: Any) -> None:
        if event.client is None:  # a value set here (the user's moves have a client)
            return
        self._duration_set(float(self.duration.value))

    def _duration_set(self, duration: float) -> None:
        """The run's duration [s] is ``duration``: the periods control follows, and a run."""
        if float(self.duration.value) != duration:
            self.duration.value = duration
        if self.periods is not None and self._period:
            count = max(1, round(duration / self._period))
            self.periods.max = max(int(self.periods.max), count)
            self.periods.value = count
        self.show_error(None, "")
        self._changed()

    def _typed_duration(self, text: str) -> None:
        sim = self._base.simulation
        try:
            duration = read_number("duration [s]", text, sim.dt, float(self.duration.max))
        except InvalidParameterError as exc:
            self.run_error.content = f"**refused**: {exc}"
            return
        if duration != float(self.duration.value):
            self._duration_set(duration)

    def _periods_moved(self, event: Any) -> None:
        if event.client is None or self._period is None:
            return
        self._periods_set(int(self.periods.value))

    def _periods_set(self, count: int) -> None:
        assert self._period is not None
        duration = count * self._period
        self.periods.max = max(int(self.periods.max), count)
        if int(self.periods.value) != count:
            self.periods.value = count
        self.duration.max = max(float(self.duration.max), duration)
        self.duration.value = duration
        self.show_error(None, "")
        self._changed()

    def _typed_periods(self, text: str) -> None:
        try:
            count = int(read_number("periods", text, 1, None, whole=True))
        except InvalidParameterError as exc:
            self.run_error.content = f"**refused**: {exc}"
            return
        if count != int(self.periods.value):
            self._periods_set(count)

    def gains(self) -> dict[str, Any]:
        """The gains the controls ask for (a matrix gain with its off-diagonal terms)."""
        return self._gains.gains()

    def spec(self) -> tuple[RunSpec, float]:
        """The run the controls describe and its payload [kg].

        Raises:
            InvalidParameterError: a setting the plant refuses (a push window that ends
                before it starts).
        """
        base = self._base
        simulation = dataclasses.replace(base.simulation, duration=float(self.duration.value))
        gains = dict(base.gains) | self.gains()
        spec = dataclasses.replace(
            base, gains=tuple(gains.items()), plant=self.plant.options(), simulation=simulation
        )
        return spec, self.plant.payload_kg

    def show_error(self, gain: str | None, text: str) -> None:
        """``text`` next to the controls of ``gain`` (None: the run's or the plant's settings,
        where the refused one is); "" clears every refusal."""
        target = self.gain_errors.get(gain, self.run_error) if gain is not None else self.run_error
        if gain is None and self.plant.error.content:
            target = self.plant.error
        for handle in (*self.gain_errors.values(), self.run_error, self.plant.error):
            if handle.content.startswith("**refused**") or handle is target:
                handle.content = ""
        if text:
            target.content = f"**refused**: {text}"


__all__ = ["Panel"]
