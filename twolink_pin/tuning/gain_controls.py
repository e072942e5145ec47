"""The gains' controls in Viser's GUI: a slider per control of :mod:`.knobs` and, under each
gain, its box ``NAME =``.

A slider moves on its rule's grid (:mod:`.steps`): whatever value the page's slider sends (an
arrow key's ``value ± step``, a drag), :func:`~.steps.snapped` makes it the next grid value
in that direction, and the slider is given the step and decimals of its new place. A gain
declared a multiple of another (mpc's horizon, of its knot interval) steps by that gain's
value, and when that gain moves it is rounded to the nearest whole multiple (a note says so).

A gain that is one word of a few (``GainSpec.choices``, e.g. ``on_infeasible``) is a
dropdown of them. The number box beside a slider shows its value to the digits that matter; a value typed into
it (:mod:`.typed_js`, :mod:`.typed`) runs as typed, on Enter or when the box loses focus. The
box ``NAME =`` shows the whole gain (a matrix as its rows) and takes one typed
(:func:`~.knobs.parse_typed`); text that reads as what the box already shows changes nothing
(a value shown rounded keeps running with every digit). A typed value beyond a slider's end
moves that end; a refused one is named next to the gain."""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError
from twolink_pin.tuning.knobs import Knob, format_typed, gains_from, parse_typed
from twolink_pin.tuning.steps import precision, shown, slider_step, snapped
from twolink_pin.tuning.typed import Channel, read_number
from twolink_pin.tuning.typed_js import TYPED_SUFFIX

HELP = (
    "*arrow keys: one step (about 12 %; a horizon: one knot) · a number typed into any box runs "
    "on Enter · `NAME =` takes a gain's whole value*"
)
"""The line above the gains: how the controls move."""


class GainControls:
    """The controls of ``knobs`` in the GUI's current container; ``changed()`` is called
    when the user moves one.

    Args:
        matrices: The full value ``(k, k)`` of each matrix gain (:func:`~.knobs.matrices_of`):
            its off-diagonal terms run with the diagonal the sliders set.
        channel: Where the typed text of the sliders' boxes arrives.
    """

    def __init__(
        self,
        gui: Any,
        knobs: list[Knob],
        changed: Callable[[], None],
        matrices: dict[str, np.ndarray] | None,
        channel: Channel,
        choices: dict[str, tuple[tuple[str, ...], str]] | None = None,
    ) -> None:
        self._knobs = knobs
        self._changed = changed
        self._matrices = {name: np.array(m, dtype=float) for name, m in (matrices or {}).items()}
        self._now = [knob.value for knob in knobs]  # each slider's value before the page's move
        self._lock = threading.RLock()  # the page's moves arrive on Viser's threads: one at a time
        self.sliders: list[Any] = []
        self.errors: dict[str, Any] = {}
        self.typed: dict[str, Any] = {}
        gui.add_markdown(HELP)
        for i, knob in enumerate(knobs):
            slider = gui.add_slider(knob.label, knob.low, knob.high, knob.step, knob.value, hint=knob.hint)
            slider.precision = precision(knob.rule, knob.value, self._of(knob))
            slider.on_update(self._moved)
            self.sliders.append(slider)
            channel.register(knob.label, functools.partial(self._typed_into_slider, i))
            if i + 1 == len(knobs) or knobs[i + 1].gain != knob.gain:
                box = gui.add_text(f"{knob.gain}{TYPED_SUFFIX}", format_typed(self._shown(knob.gain)))
                box.on_update(lambda event, name=knob.gain: self._typed(event, name))
                self.typed[knob.gain] = box
                self.errors[knob.gain] = gui.add_markdown("")
        self.words: dict[str, Any] = {}
        for name, (options, value) in (choices or {}).items():  # a gain that is a word: a dropdown
            self.words[name] = gui.add_dropdown(name, options, initial_value=value)
            self.words[name].on_update(lambda event: None if event.client is None else changed())
            self.errors[name] = gui.add_markdown("")

    def gains(self) -> dict[str, Any]:
        """The gains the controls ask for (a matrix gain with its off-diagonal terms, a gain
        that is a word as the word chosen)."""
        words = {name: str(dropdown.value) for name, dropdown in self.words.items()}
        return gains_from(self._knobs, self._settings(), self._matrices) | words

    def _settings(self) -> dict[int, float]:
        return {i: float(s.value) for i, s in enumerate(self.sliders)}

    def _of(self, knob: Knob) -> float | None:
        """The value of the gain ``knob`` is a multiple of (None: it is not one)."""
        if knob.rule.kind != "multiple":
            return None
        index = next((i for i, k in enumerate(self._knobs) if k.gain == knob.rule.of and not k.scale), None)
        if index is None:
            return None
        return float(self.sliders[index].value if index < len(self.sliders) else self._knobs[index].value)

    def _shown(self, name: str) -> Any:
        """The value of gain ``name`` the controls ask for: a matrix gain as ``compare`` and the
        command line name it, its diagonal (k numbers) when diagonal, else ``(k, k)``."""
        value = gains_from(self._knobs, self._settings(), self._matrices)[name]
        full = self._matrices.get(name)
        if full is not None:
            k = full.shape[0]
            array = np.asarray(value, dtype=float)
            return array if array.size == k else array.reshape(k, k)
        return value

    def _place(self, i: int, value: float) -> None:
        """Slider ``i`` at ``value``: its ends moved to reach it, its step and decimals those of
        its new place on the grid."""
        knob, slider = self._knobs[i], self.sliders[i]
        of = self._of(knob)
        if value > slider.max:
            slider.max = value
        if knob.rule.kind == "multiple" and of is not None and of > 0:  # its low end: one of the other gain
            slider.min = min(of, value)
        elif value < slider.min:
            slider.min = value
        slider.step = max(slider_step(knob.rule, value, of), 1e-12 * max(abs(value), 1.0))
        slider.precision = precision(knob.rule, value, of)
        if float(slider.value) != value:
            slider.value = value
        self._now[i] = value

    def _refit_multiples(self, moved: str) -> None:
        """The gains that are multiples of ``moved`` rounded to its new value's whole
        multiples (a note says so beside each one that changed)."""
        for i, knob in enumerate(self._knobs):
            of = self._of(knob)
            if knob.rule.of != moved or of is None or of <= 0:
                continue
            before = float(self.sliders[i].value)
            count = max(1, round(before / of))
            self._place(i, count * of)
            if count * of != before:
                self.typed[knob.gain].value = format_typed(self._shown(knob.gain))
                note = f"{knob.gain} rounded to {count} × {moved} = {shown(count * of)} (was {shown(before)})"
                self.errors[knob.gain].content = note

    def _moved(self, event: Any) -> None:
        """A slider the page moved: onto its grid, then a run."""
        if event.client is None:  # a value set here (the page's moves have a client)
            return
        with self._lock:
            self._moved_to(event)

    def _moved_to(self, event: Any) -> None:
        i = next(i for i, s in enumerate(self.sliders) if s is event.target)
        knob = self._knobs[i]
        sent = float(self.sliders[i].value)
        value = snapped(knob.rule, self._now[i], sent, self._of(knob))
        value = min(max(value, float(self.sliders[i].min)), float(self.sliders[i].max))
        self._place(i, value)
        self.errors[knob.gain].content = ""
        self._refit_multiples(knob.gain)
        self.typed[knob.gain].value = format_typed(self._shown(knob.gain))
        self._changed()

    def _typed_into_slider(self, i: int, _index: int, text: str) -> None:
        """A number typed into slider ``i``'s box: the slider takes it as typed (its ends move
        to reach it) and the law runs with it; text that is no number is named."""
        with self._lock:
            self._typed_number(i, text)

    def _typed_number(self, i: int, text: str) -> None:
        knob = self._knobs[i]
        try:
            value = read_number(knob.label.partition(" [")[0], text)
        except InvalidParameterError as exc:
            self.show_error(knob.gain, str(exc))
            return
        if value == float(self.sliders[i].value):
            return
        self._place(i, value)
        self.errors[knob.gain].content = ""
        self._refit_multiples(knob.gain)
        self.typed[knob.gain].value = format_typed(self._shown(knob.gain))
        self._changed()

    def _typed(self, event: Any, name: str) -> None:
        """A value typed in gain ``name``'s box (sent on Enter or blur): the sliders take it
        (their ends move to reach it) and the law runs with it; a refused one is named."""
        if event.client is None:
            return
        with self._lock:
            self._typed_gain(name)

    def _typed_gain(self, name: str) -> None:
        text = str(self.typed[name].value)
        if text.strip() == format_typed(self._shown(name)):  # what the box shows: nothing changed
            return
        indices = [i for i, k in enumerate(self._knobs) if k.gain == name]
        components = [i for i in indices if self._knobs[i].component is not None]
        scales = [i for i in indices if self._knobs[i].scale]
        try:
            value = parse_typed(
                name, text, len(components) if components else None, matrix=name in self._matrices
            )
        except InvalidParameterError as exc:
            self.show_error(name, str(exc))
            return
        array = np.asarray(value, dtype=float)
        if name in self._matrices:
            self._matrices[name] = np.array(array) if array.ndim == 2 else np.diag(array)
            values = [float(x) for x in np.diag(self._matrices[name])]
        else:
            values = [float(x) for x in array.reshape(-1)]
        for i, x in zip(components or indices, values, strict=True):
            self._place(i, x)
        for i in scales:
            self._place(i, 1.0)
        self.errors[name].content = ""
        self._refit_multiples(name)
        self.typed[name].value = format_typed(self._shown(name))  # what runs, as the box shows it
        self._changed()

    def show_error(self, gain: str, text: str) -> None:
        """``text`` (a refusal) next to the controls of ``gain``."""
        self.errors[gain].content = f"**refused**: {text}" if text else ""


__all__ = ["HELP", "GainControls"]
