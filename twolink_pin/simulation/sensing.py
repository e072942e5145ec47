"""The law's force sensor and force reference on a plant with a scene: ``LawInput.contact``.

A plant whose scene has surfaces (:mod:`twolink_pin.contact`) gives every law, at every
evaluation, a :class:`~twolink_pin.controllers.contact_input.ContactInput`:

* ``wrench`` — what the force sensor reads at the state the law is evaluated at: the plant's
  contact wrench there (the same force the plant's acceleration feels over that stage: a
  spring–damper contact is a function of the state, so the reading has no delay), plus the
  step's force noise (``--sensor-noise …,SIGMA_F``), read from the **true** state (the noise on
  ``q``, ``q̇`` is the joint encoders', not the force sensor's);
* ``normal`` — the outward normal of the surface the force reference is on;
* ``force_des`` — the reference's normal force [N] at that instant (0 without a reference).

:class:`ForceSensor` builds the reference's rows where the engine samples the reference (once per
block, on the half-step grid) and wraps the law's call so that the wrench is filled in. A plant
of another engine gives the same input by answering :meth:`ForceSensor.measure`'s question with
its own contact.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from twolink_pin.contact.compliant import CompliantContact
from twolink_pin.controllers import Controller, LawInput
from twolink_pin.controllers.contact_input import ContactInput
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant import Plant
from twolink_pin.simulation.containment import read_only
from twolink_pin.trajectory import Trajectory
from twolink_pin.trajectory.force import ForceReference


class ForceSensor:
    """The force sensor of N runs and the force reference's rows (see the module docstring).

    Args:
        contact: The plant's contact (its scene's surfaces).
        reference: The force reference (None: ``force_des`` is 0), on one of the scene's surfaces.
        noise: The step's force noise (N, 6), when asked (the plant's events'); None: none.
    """

    def __init__(
        self,
        contact: CompliantContact,
        reference: ForceReference | None,
        noise: Callable[[], np.ndarray | None] | None = None,
    ) -> None:
        scene = contact.scene
        surface = scene.surfaces[scene.index(reference.surface) if reference is not None else 0]
        self.contact = contact
        self.reference = reference
        self.normal = read_only(np.array([surface.normal]))
        """The reference surface's outward normal, (1, 3)."""
        self._noise = noise
        self._none = ContactInput(None, self.normal, read_only(np.zeros((1, 1))))  # type: ignore[arg-type]

    def rows(self, t: np.ndarray) -> list[ContactInput]:
        """The reference's part of the contact input at times ``t`` [s] (K,): the normal and
        ``force_des`` (1, 1) [N], the wrench left to :meth:`wrap`."""
        if self.reference is None:
            return [self._none] * len(t)
        force = read_only(self.reference.sample(t).reshape(-1, 1, 1))
        return [ContactInput(None, self.normal, f) for f in force]  # type: ignore[arg-type]

    def measure(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """What the sensor reads at the state ``(q, q̇)`` (N, nv): the contact wrench the end
        effector applies to the surfaces [N; N·m] plus the step's noise, (N, 6), read-only."""
        wrench = self.contact(q, v).wrench  # read-only already
        noise = None if self._noise is None else self._noise()
        return wrench if noise is None else read_only(wrench + noise)

    def wrap(self, law: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
        """``law`` (the engine's call of the law) with the sensor's reading in ``x.contact``
        (the engine's input carries the reference's part there)."""
        new, contact = tuple.__new__, self.contact
        measure = self.measure if self._noise is not None else (lambda q, v: contact(q, v).wrench)
        i = LawInput._fields.index("contact")  # the fields after it (the preview) kept

        def sensed(x: LawInput, terms: Any) -> Any:
            part: Any = x[i]  # the reference's part: (None, normal, force_des)
            reading = new(ContactInput, (measure(x[1], x[2]), part[1], part[2]))
            return law(new(LawInput, (*x[:i], reading, *x[i + 1 :])), terms)

        return sensed


def check_contact_setup(controller: Controller, plant: Plant, trajectory: Trajectory) -> None:
    """Refuse a run whose law, scene and force reference do not go together: a law that controls a
    force (:attr:`~twolink_pin.controllers.Controller.force_control`) without a surface or without a
    force reference, a force reference without a surface or on a surface the scene lacks.

    Raises:
        InvalidParameterError: naming what is missing and how to give it.
    """
    scene, reference = plant.scene, trajectory.force_reference
    law = f"law '{controller.name}'"
    if controller.force_control and scene is None:
        raise InvalidParameterError(
            "scene", None, f"a surface to press on: {law} controls a contact force (--scene FILE or --wall …)"
        )
    if reference is not None and scene is None:
        raise InvalidParameterError(
            "force reference",
            f"{max(reference.values):g} N at most",
            "a surface to press on (--scene FILE or --wall …): a force reference without one means nothing",
        )
    if reference is not None and scene is not None:
        scene.index(reference.surface)  # the surface it names exists (or the scene has one)
    if controller.force_control and reference is None:
        raise InvalidParameterError(
            "force reference",
            None,
            f"a desired normal force for {law}: a trajectory file's 'force' column [N] (docs/contact.md)",
        )


__all__ = ["ForceSensor", "check_contact_setup"]
