"""The options of a world the arm touches: ``--scene FILE`` and ``--wall …`` (:mod:`twolink_pin.contact`).

Each value type raises :class:`argparse.ArgumentTypeError` naming the value and the expected form
(one line on stderr, exit 2); :func:`scene_of` gives the run's
:attr:`~twolink_pin.run_spec.PlantOptions.scene`. The force sensor's noise is ``--sensor-noise``'s
third value (:mod:`twolink_pin.cli.disturbance_options`); a force reference is a trajectory file's
``force`` column (:mod:`twolink_pin.trajectory.force`).
"""

from __future__ import annotations

import argparse
from typing import Any

from twolink_pin.cli.arguments import MAX_TEXT, finite
from twolink_pin.cli.common_options import run_group
from twolink_pin.contact.scene import DEFAULT_DAMPING, DEFAULT_RADIUS, DEFAULT_STIFFNESS, Scene, Surface
from twolink_pin.errors import InvalidParameterError, TwolinkPinError


def _shown(text: str) -> str:
    return repr(text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + "…")


def wall(text: str) -> Scene:
    """``X,Y,Z:NX,NY,NZ[:K[:B[:MU]]]``: a plane through a point [m] with its outward normal, its
    stiffness [N/m], damping [N·s/m] and Coulomb μ (defaults :data:`DEFAULT_STIFFNESS`,
    :data:`DEFAULT_DAMPING`, 0)."""
    expected = (
        "X,Y,Z:NX,NY,NZ[:K[:B[:MU]]] — a point [m], the outward normal (towards the arm), the "
        f"stiffness [N/m], damping [N·s/m] and friction μ (e.g. 0.55,0,0:-1,0,0:1000:20:0.2), got {_shown(text)}"
    )
    parts = text.split(":")
    if not 2 <= len(parts) <= 5:
        raise argparse.ArgumentTypeError(f"expected {expected}")
    try:
        point, normal = (tuple(finite(x) for x in part.split(",")) for part in parts[:2])
        values = [finite(x) for x in parts[2:]]
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected finite numbers: {expected}") from None
    stiffness, damping, friction = values + [DEFAULT_STIFFNESS, DEFAULT_DAMPING, 0.0][len(values) :]
    try:
        surface = Surface(point, normal, stiffness=stiffness, damping=damping, friction=friction)
        return Scene((surface,), radius=DEFAULT_RADIUS)
    except TwolinkPinError as exc:
        raise argparse.ArgumentTypeError(f"{exc}: {expected}") from None


def add_contact_options(p: argparse.ArgumentParser) -> None:
    """The scene's options, on a command that simulates (in its run options)."""
    group = run_group(p)
    group.add_argument(
        "--scene",
        metavar="FILE",
        help="surfaces the end effector touches (TOML/JSON: points, normals, stiffness, damping, "
        "friction; docs/contact.md), with a force sensor at the end effector",
    )
    group.add_argument(
        "--wall",
        type=wall,
        metavar="X,Y,Z:NX,NY,NZ[:K[:B[:MU]]]",
        help="one plane through X,Y,Z [m] facing NX,NY,NZ, of stiffness K [N/m] (default "
        f"{DEFAULT_STIFFNESS:g}), damping B [N·s/m] (default {DEFAULT_DAMPING:g}) and friction MU (default 0)",
    )


def scene_of(args: Any) -> dict[str, Any]:
    """The scene the arguments ask for, as the :class:`~twolink_pin.run_spec.PlantOptions` field
    (none for a command without these options).

    Raises:
        InvalidParameterError: both ``--scene`` and ``--wall``.
        InputFileError: the scene file cannot be read.
    """
    path, plane = getattr(args, "scene", None), getattr(args, "wall", None)
    if path is not None and plane is not None:
        raise InvalidParameterError(
            "--wall", "with --scene", "one of --scene FILE and --wall (a scene file holds walls)"
        )
    if path is not None:
        from twolink_pin.contact.scene import read_scene

        return {"scene": read_scene(path)}
    return {"scene": plane}
