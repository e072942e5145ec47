"""The plant's controls in Viser's GUI (the folder *plant*): the engine the arm runs on
(``--plant``: Pinocchio's, MuJoCo's), the plant's friction, saturation at the effort limits,
the payload, a push (force and window), sensor noise and delay, and the
:class:`~twolink_pin.plant_options.PlantOptions` they describe.

This is the one place of the page that knows the plant's options: a new one (another
engine, contact) is a control added where :class:`PlantControls` makes the others, its number boxes
registered with the channel, and its value set in :meth:`PlantControls.options`.

A number typed into a box here runs on Enter or when the box loses focus (:mod:`.typed_js`),
read as the gain boxes read theirs; a value out of the box's range is refused next to the
folder's controls, naming what is expected."""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from typing import Any

from twolink_pin.disturbances import SensorNoise, Wrench
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant import ENGINES, FRICTION_CHOICES
from twolink_pin.plant_options import PlantOptions
from twolink_pin.tuning.typed import Channel, read_number

MAX_PUSH = 1000.0
"""Largest push force on a control [N]."""
MAX_DELAY = 100_000
"""Most steps of delay a control offers."""
MAX_PAYLOAD = 1e4
"""Heaviest payload a control offers [kg]."""


class PlantControls:
    """The plant's controls in the GUI's current container, starting from ``base``'s options
    and ``payload`` [kg]; ``changed()`` is called when the user changes one. A refused value
    is named in :attr:`error`, below them."""

    def __init__(
        self,
        gui: Any,
        base: PlantOptions,
        payload: float,
        duration: float,
        channel: Channel,
        changed: Callable[[], None],
    ) -> None:
        self._base, self._changed = base, changed
        wrench = base.wrench
        self.engine = gui.add_dropdown(
            "engine",
            tuple(ENGINES),
            initial_value=base.engine,
            hint="the simulator the arm runs on (--plant)",
        )
        self.friction = gui.add_dropdown("plant friction", FRICTION_CHOICES, initial_value=base.friction)
        self.saturate = gui.add_checkbox("saturate at the effort limits", base.saturate)
        self.payload = gui.add_number("payload [kg]", payload, min=0.0, max=MAX_PAYLOAD, step=0.1)
        self.push = gui.add_vector3(
            "push force [N]",
            tuple(float(x) for x in (wrench.force[:3] if wrench else (0.0, 0.0, 0.0))),
            min=(-MAX_PUSH,) * 3,
            max=(MAX_PUSH,) * 3,
            step=1.0,
        )
        self.push_from = gui.add_number("push from [s]", float(wrench.start) if wrench else 1.0, step=0.1)
        stop = float(wrench.stop) if wrench and math.isfinite(wrench.stop) else (duration if wrench else 1.5)
        self.push_to = gui.add_number("push to [s]", stop, step=0.1)
        noise = base.sensor_noise
        self.noise = gui.add_number(
            "sensor noise σ_q [rad]", float(noise.sigma_q) if noise else 0.0, min=0.0, max=1.0, step=1e-4
        )
        self.delay = gui.add_number("delay [steps]", int(base.delay), min=0, max=MAX_DELAY, step=1)
        self.error = gui.add_markdown("")
        for handle in (
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
        ranges: list[tuple[Any, float | None, float | None, bool]] = [
            (self.payload, 0.0, MAX_PAYLOAD, False),
            (self.push_from, 0.0, None, False),
            (self.push_to, 0.0, None, False),
            (self.noise, 0.0, 1.0, False),
            (self.delay, 0, MAX_DELAY, True),
        ]
        for handle, low, high, whole in ranges:
            channel.register(handle.label, functools.partial(self._typed, handle, low, high, whole))
        channel.register(self.push.label, self._typed_push)

    def _refuse(self, text: str) -> None:
        """``text`` (a refused value's message) below the plant's controls; "" clears it."""
        self.error.content = f"**refused**: {text}" if text else ""

    def _moved(self, event: Any) -> None:
        if event.client is not None:  # the page's moves have a client; values set here none
            self._refuse("")
            self._changed()

    def _typed(
        self, handle: Any, low: float | None, high: float | None, whole: bool, _index: int, text: str
    ) -> None:
        """A number typed into ``handle``'s box: taken and run, or refused naming the range."""
        try:
            value = read_number(handle.label, text, low, high, whole=whole)
        except InvalidParameterError as exc:
            self._refuse(str(exc))
            return
        self._refuse("")
        if value != float(handle.value):
            handle.value = int(value) if whole else value
            self._changed()

    def _typed_push(self, index: int, text: str) -> None:
        """A number typed into one of the push force's three boxes (x, y, z)."""
        try:
            value = read_number(f"push force [N] {'xyz'[index % 3]}", text, -MAX_PUSH, MAX_PUSH)
        except InvalidParameterError as exc:
            self._refuse(str(exc))
            return
        self._refuse("")
        force = list(self.push.value)
        if 0 <= index < 3 and force[index] != value:
            force[index] = value
            self.push.value = tuple(force)
            self._changed()

    @property
    def payload_kg(self) -> float:
        """The payload the control asks for [kg]."""
        return float(self.payload.value)

    def options(self) -> PlantOptions:
        """The plant the controls describe.

        Raises:
            InvalidParameterError: a setting the plant refuses (a push window that ends
                before it starts), also named below the controls.
        """
        try:
            return self._options()
        except InvalidParameterError as exc:
            self._refuse(str(exc))
            raise

    def _options(self) -> PlantOptions:
        base = self._base
        wrench = base.wrench
        force = tuple(float(x) for x in self.push.value)
        if any(force):
            moments = tuple(wrench.force[3:]) if wrench is not None else ()
            wrench = Wrench(force + moments, float(self.push_from.value), float(self.push_to.value))
        elif wrench is not None and any(wrench.force[3:]):
            wrench = dataclasses.replace(wrench, force=(0.0, 0.0, 0.0, *wrench.force[3:]))
        else:
            wrench = None
        sigma = float(self.noise.value)
        noise = base.sensor_noise
        if sigma or (noise is not None and noise.sigma_v):
            noise = SensorNoise(sigma, noise.sigma_v if noise else 0.0, seed=noise.seed if noise else 0)
        else:
            noise = None
        return dataclasses.replace(
            base,
            engine=str(self.engine.value),
            friction=str(self.friction.value),
            saturate=bool(self.saturate.value),
            wrench=wrench,
            sensor_noise=noise,
            delay=int(self.delay.value),
        )


__all__ = ["MAX_PUSH", "PlantControls"]
