"""The tuner's controls in Viser's GUI: the law's gains (:mod:`.knobs`) and the run's
settings (periods, duration, plant friction, saturation, payload, a push, sensor noise,
delay), and the :class:`~twolink_pin.run_spec.RunSpec` they describe. Each control is
labelled with the gain's name as ``twolink-pin controllers`` prints it and its unit; a
slider moves with the arrow keys; each gain's box ``NAME =`` shows its whole value (a
matrix as its rows) and takes one typed, sent when Enter is pressed or the box loses focus
(:mod:`.typed_js`) and read by :func:`~.knobs.parse_typed` (a refused one is named next to
the box, which keeps what was typed); a typed value beyond a slider's end moves that end.
``periods`` sets the duration to a whole number of the reference's periods."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.disturbances import SensorNoise, Wrench
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant import ENGINES
from twolink_pin.run_spec import FRICTION_CHOICES
from twolink_pin.tuning.knobs import Knob, format_typed, gains_from, parse_typed
from twolink_pin.tuning.typed_js import TYPED_SUFFIX, typed_html

if TYPE_CHECKING:
    from twolink_pin.run_spec import RunSpec

MAX_PUSH = 1000.0
"""Largest push force on a control [N]."""
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
        period: The reference's period [s] (the periods control's unit).
        order: Where the gains' folder sits in the page (Viser's ``order``); the run's
            settings sit at ``order + 10``.
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
    ) -> None:
        self._knobs = knobs
        self._base = base
        self._changed = changed
        self._matrices = {name: np.array(m, dtype=float) for name, m in (matrices or {}).items()}
        self._period = period if period and math.isfinite(period) and period > 0 else None
        gui = server.gui
        gui.add_html(typed_html(), order=order - 0.5)
        self.sliders: list[Any] = []
        self.gain_errors: dict[str, Any] = {}
        self.typed: dict[str, Any] = {}
        self.periods: Any = None
        with gui.add_folder("gains", order=order):
            if self._period:
                count = max(1, round(base.simulation.duration / self._period))
                self.periods = gui.add_slider(
                    "periods",
                    1,
                    max(MAX_PERIODS, count),
                    1,
                    count,
                    hint=f"the run's duration in periods of the reference ({self._period:g} s each)",
                )
                self.periods.on_update(self._periods_moved)
            for knob in knobs:
                slider = gui.add_slider(
                    knob.label, knob.low, knob.high, knob.step, knob.value, hint=knob.hint
                )
                slider.on_update(self._moved_gain)
                self.sliders.append(slider)
                last = knob is knobs[-1] or knobs[knobs.index(knob) + 1].gain != knob.gain
                if last:
                    box = gui.add_text(
                        f"{knob.gain}{TYPED_SUFFIX}",
                        format_typed(self._shown(knob.gain)),
                        hint=f"{knob.gain}'s whole value: a number, one per component, or a matrix row "
                        "by row (rows split by ;); runs on Enter or when the box loses focus",
                    )
                    box.on_update(lambda event, name=knob.gain: self._typed(event, name))
                    self.typed[knob.gain] = box
                    self.gain_errors[knob.gain] = gui.add_markdown("")
        self._add_run_controls(gui, base, payload, order + 10)

    def _add_run_controls(self, gui: Any, base: RunSpec, payload: float, order: float) -> None:
        """The run's settings, in a folder at ``order``."""
        plant, sim = base.plant, base.simulation
        wrench = plant.wrench
        with gui.add_folder("run", expand_by_default=False, order=order):
            self.duration = gui.add_number(  # bounded: a run in flight is not interrupted
                "duration [s]", sim.duration, min=sim.dt, max=max(MAX_DURATION, sim.duration), step=0.1
            )
            self.engine = gui.add_dropdown(
                "plant",
                tuple(ENGINES),
                initial_value=plant.engine,
                hint="the simulator the arm runs on (--plant)",
            )
            self.friction = gui.add_dropdown("plant friction", FRICTION_CHOICES, initial_value=plant.friction)
            self.saturate = gui.add_checkbox("saturate at the effort limits", plant.saturate)
            self.payload = gui.add_number("payload [kg]", payload, min=0.0, max=1e4, step=0.1)
            self.push = gui.add_vector3(
                "push force [N]",
                tuple(float(x) for x in (wrench.force[:3] if wrench else (0.0, 0.0, 0.0))),
                min=(-MAX_PUSH,) * 3,
                max=(MAX_PUSH,) * 3,
                step=1.0,
            )
            self.push_from = gui.add_number("push from [s]", float(wrench.start) if wrench else 1.0, step=0.1)
            self.push_to = gui.add_number(
                "push to [s]",
                float(wrench.stop)
                if wrench and math.isfinite(wrench.stop)
                else (sim.duration if wrench else 1.5),
                step=0.1,
            )
            noise = plant.sensor_noise
            self.noise = gui.add_number(
                "sensor noise σ_q [rad]", float(noise.sigma_q) if noise else 0.0, min=0.0, max=1.0, step=1e-4
            )
            self.delay = gui.add_number("delay [steps]", int(plant.delay), min=0, max=100_000, step=1)
            self.run_error = gui.add_markdown("")
        for handle in (
            self.duration,
            self.engine,
            self.friction,
            self.saturate,
            self.payload,
            self.push,
            self.push_from,
            self.push_to,
            self.noise,
            self.delay,
        ):
            handle.on_update(self._moved)

    def _moved(self, event: Any) -> None:
        if event.client is None:  # a value set here (the user's moves have a client)
            return
        if event.target is self.duration and self.periods is not None and self._period:
            count = max(1, round(float(self.duration.value) / self._period))
            self.periods.max = max(int(self.periods.max), count)
            self.periods.value = count
        self._changed()

    def _periods_moved(self, event: Any) -> None:
        if event.client is None or self._period is None:
            return
        duration = int(self.periods.value) * self._period
        self.duration.max = max(float(self.duration.max), duration)
        self.duration.value = duration
        self._changed()

    def _moved_gain(self, event: Any) -> None:
        if event.client is None:
            return
        index = next(i for i, s in enumerate(self.sliders) if s is event.target)
        name = self._knobs[index].gain
        self.typed[name].value = format_typed(self._shown(name))
        self.gain_errors[name].content = ""
        self._changed()

    def _shown(self, name: str) -> Any:
        """The value of gain ``name`` the controls ask for (a matrix gain: ``(k, k)``)."""
        settings = {i: float(s.value) for i, s in enumerate(self.sliders)}
        value = gains_from(self._knobs, settings, self._matrices)[name]
        full = self._matrices.get(name)
        if full is not None:
            k = full.shape[0]
            array = np.asarray(value, dtype=float)
            return np.diag(array) if array.size == k else array.reshape(k, k)
        return value

    def _typed(self, event: Any, name: str) -> None:
        """A value typed in gain ``name``'s box (sent on Enter or blur): the sliders take it
        (their ends move to reach it) and the law runs with it; a refused one is named."""
        if event.client is None:
            return
        text = str(self.typed[name].value)
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
            slider = self.sliders[i]
            if x > slider.max:
                slider.max = x
            if x < slider.min:
                slider.min = x
            slider.value = x
        for i in scales:
            self.sliders[i].value = 1.0
        self.typed[name].value = format_typed(self._shown(name))  # what runs, as the box shows it
        self.gain_errors[name].content = ""
        self._changed()

    def gains(self) -> dict[str, Any]:
        """The gains the controls ask for (a matrix gain with its off-diagonal terms)."""
        return gains_from(
            self._knobs, {i: float(s.value) for i, s in enumerate(self.sliders)}, self._matrices
        )

    def spec(self) -> tuple[RunSpec, float]:
        """The run the controls describe and its payload [kg].

        Raises:
            InvalidParameterError: a setting the plant refuses (a push window that ends
                before it starts).
        """
        base = self._base
        wrench = base.plant.wrench
        force = tuple(float(x) for x in self.push.value)
        if any(force):
            moments = tuple(wrench.force[3:]) if wrench is not None else ()
            wrench = Wrench(force + moments, float(self.push_from.value), float(self.push_to.value))
        elif wrench is not None and any(wrench.force[3:]):
            wrench = dataclasses.replace(wrench, force=(0.0, 0.0, 0.0, *wrench.force[3:]))
        else:
            wrench = None
        sigma = float(self.noise.value)
        noise = base.plant.sensor_noise
        if sigma or (noise is not None and noise.sigma_v):
            noise = SensorNoise(sigma, noise.sigma_v if noise else 0.0, seed=noise.seed if noise else 0)
        else:
            noise = None
        plant = dataclasses.replace(
            base.plant,
            engine=str(self.engine.value),
            friction=str(self.friction.value),
            saturate=bool(self.saturate.value),
            wrench=wrench,
            sensor_noise=noise,
            delay=int(self.delay.value),
        )
        simulation = dataclasses.replace(base.simulation, duration=float(self.duration.value))
        gains = dict(base.gains) | self.gains()
        spec = dataclasses.replace(base, gains=tuple(gains.items()), plant=plant, simulation=simulation)
        return spec, float(self.payload.value)

    def show_error(self, gain: str | None, text: str) -> None:
        """``text`` next to the controls of ``gain`` (None: the run's settings); "" clears."""
        target = self.gain_errors.get(gain, self.run_error) if gain is not None else self.run_error
        for handle in (*self.gain_errors.values(), self.run_error):
            handle.content = ""
        if text:
            target.content = f"**refused**: {text}"


__all__ = ["Panel"]
