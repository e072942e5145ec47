"""The tuner's controls in Viser's GUI: the law's gains (:mod:`.knobs`) and the run's
settings (duration, plant friction, saturation, payload, a push, sensor noise, delay), and
the :class:`~twolink_pin.run_spec.RunSpec` they describe. Each control is labelled with
the gain's name as ``twolink-pin controllers`` prints it and its unit; a slider moves with
the arrow keys and its number box takes a typed value."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from twolink_pin.disturbances import SensorNoise, Wrench
from twolink_pin.run_spec import FRICTION_CHOICES
from twolink_pin.tuning.knobs import Knob, gains_from

if TYPE_CHECKING:
    from twolink_pin.run_spec import RunSpec

MAX_PUSH = 1000.0
"""Largest push force on a control [N]."""
MAX_DURATION = 60.0
"""Longest run the duration control offers [s] (more when the command line asks for more)."""


class Panel:
    """The controls of ``knobs`` and of the run settings of ``base`` in ``server``'s GUI;
    ``changed()`` is called when the user moves one."""

    def __init__(
        self, server: Any, knobs: list[Knob], base: RunSpec, payload: float, changed: Callable[[], None]
    ) -> None:
        self._knobs = knobs
        self._base = base
        self._changed = changed
        gui = server.gui
        self.sliders: list[Any] = []
        self.gain_errors: dict[str, Any] = {}
        with gui.add_folder("gains"):
            for knob in knobs:
                slider = gui.add_slider(
                    knob.label, knob.low, knob.high, knob.step, knob.value, hint=knob.hint
                )
                slider.on_update(self._moved)
                self.sliders.append(slider)
                last = knob is knobs[-1] or knobs[knobs.index(knob) + 1].gain != knob.gain
                if last:
                    self.gain_errors[knob.gain] = gui.add_markdown("")
        plant, sim = base.plant, base.simulation
        wrench = plant.wrench
        with gui.add_folder("run", expand_by_default=False):
            self.duration = gui.add_number(  # bounded: a run in flight is not interrupted
                "duration [s]", sim.duration, min=sim.dt, max=max(MAX_DURATION, sim.duration), step=0.1
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
        if event.client is not None:  # the user's move (a value set here has no client)
            self._changed()

    def gains(self) -> dict[str, Any]:
        """The gains the controls ask for."""
        return gains_from(self._knobs, {i: float(s.value) for i, s in enumerate(self.sliders)})

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
