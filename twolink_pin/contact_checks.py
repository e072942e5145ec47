"""What a run with a scene or a force reference must be, checked before any run: a refusal names
the option and says what would make it mean something (:meth:`RunSpec.check_effective
<twolink_pin.run_spec.RunSpec.check_effective>` calls :func:`check_contact`).

* a law that controls a force (:attr:`~twolink_pin.controllers.Controller.force_control`) needs a
  surface (``--scene``, ``--wall``) and a force reference (a trajectory file's ``force`` column);
* a force reference needs a surface, names one the scene has, and a law that uses it among those
  that run (in ``compare`` and ``report`` the laws that cannot use it run on the same reference,
  their force measured against it: the contact metrics);
* the force sensor's noise (``--sensor-noise …,SIGMA_F``) needs a scene;
* a scene needs the RK4 engine (the contact acts between its stages).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from twolink_pin.controllers import Controller
from twolink_pin.errors import InvalidParameterError
from twolink_pin.plant_options import PlantOptions
from twolink_pin.simulation import SimulationConfig
from twolink_pin.trajectory import Trajectory

SCENE_OPTIONS = "--scene FILE or --wall X,Y,Z:NX,NY,NZ"
"""How a command is given a surface."""


def check_contact(
    plant: PlantOptions,
    simulation: SimulationConfig,
    classes: Sequence[type[Controller[Any]]],
    trajectory: Trajectory | None = None,
) -> None:
    """Refuse a scene, a force reference or a force law that would do nothing or cannot run (see
    the module docstring), for the laws ``classes`` that run on ``plant`` along ``trajectory``
    (None: not known yet, its checks left out).

    Raises:
        InvalidParameterError: the option, its value and what it needs.
    """
    scene = plant.scene
    force_laws = [cls.name for cls in classes if cls.force_control]
    noise = plant.sensor_noise
    if noise is not None and noise.sigma_f > 0 and scene is None:
        raise InvalidParameterError(
            "--sensor-noise",
            f"SIGMA_F = {noise.sigma_f:g} N",
            f"a force sensor to add it to: a scene ({SCENE_OPTIONS})",
        )
    if scene is not None and simulation.method != "rk4":
        raise InvalidParameterError(
            "--method", simulation.method, "rk4 with a scene (the contact acts between its stages)"
        )
    if force_laws and scene is None:
        raise InvalidParameterError(
            "law", force_laws[0], f"a surface to press on: it controls a contact force ({SCENE_OPTIONS})"
        )
    if trajectory is None:
        return
    reference = trajectory.force_reference
    if force_laws and reference is None:
        raise InvalidParameterError(
            "--trajectory",
            "no force reference",
            f"a trajectory file with a 'force' column [N] for {', '.join(force_laws)} (docs/contact.md)",
        )
    if reference is None:
        return
    if scene is None:
        raise InvalidParameterError(
            "--trajectory",
            "a 'force' column",
            f"a surface to press on ({SCENE_OPTIONS}): a force reference without one means nothing",
        )
    scene.index(reference.surface)
    if not force_laws:
        names = ", ".join(cls.name for cls in classes)
        raise InvalidParameterError(
            "--trajectory",
            "a 'force' column",
            f"a law that controls a force (force, hybrid) among those that run ({names}): no other law reads it",
        )


__all__ = ["SCENE_OPTIONS", "check_contact"]
