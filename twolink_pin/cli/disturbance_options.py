"""The options of a plant that pushes back: ``--wrench``, ``--payload-step``,
``--sensor-noise``, ``--noise-seed``, ``--delay`` (:mod:`twolink_pin.disturbances`), and the
scene it touches (``--scene``, ``--wall``: :mod:`twolink_pin.cli.contact_options`).

Each value type raises :class:`argparse.ArgumentTypeError` naming the value and the expected
form (one line on stderr, exit 2); :func:`plant_events` gives them to the run's
:class:`~twolink_pin.run_spec.PlantOptions`.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from twolink_pin.cli.arguments import MAX_TEXT, finite, whole
from twolink_pin.cli.common_options import run_group
from twolink_pin.cli.contact_options import add_contact_options, scene_of
from twolink_pin.disturbances import PayloadStep, Wrench
from twolink_pin.errors import InvalidParameterError, TwolinkPinError

MAX_FORCE = 1e6
"""Largest force [N] or moment [N·m] accepted on the command line."""
MAX_MASS = 1e4
"""Largest payload step accepted on the command line [kg]."""
MAX_DELAY = 100_000
"""Largest delay accepted on the command line [steps]."""


def _shown(text: str) -> str:
    return repr(text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + "…")


def wrench(text: str) -> Wrench:
    """``FX,FY,FZ[,MX,MY,MZ][@T0:T1]`` [N, N·m, s], world-aligned, on the end effector; without
    ``@`` for the whole run, ``T1`` empty for "until the end"."""
    expected = f"FX,FY,FZ[,MX,MY,MZ][@T0:T1] in N, N·m and s (e.g. 0,0,-20@1:2), got {_shown(text)}"
    values, _, window = text.partition("@")
    parts = values.split(",")
    if len(parts) not in (3, 6):
        raise argparse.ArgumentTypeError(f"expected 3 or 6 numbers: {expected}")
    try:
        force = tuple(finite(x) for x in parts)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected finite numbers: {expected}") from None
    if any(abs(x) > MAX_FORCE for x in force):
        raise argparse.ArgumentTypeError(f"expected forces and moments within ±{MAX_FORCE:g}: {expected}")
    start, stop = 0.0, math.inf
    if window:
        first, colon, last = window.partition(":")
        if not colon:
            raise argparse.ArgumentTypeError(f"expected a window T0:T1: {expected}")
        try:
            start = finite(first) if first else 0.0
            stop = finite(last) if last else math.inf
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"expected times T0:T1: {expected}") from None
    try:
        return Wrench(force, start, stop)
    except TwolinkPinError as exc:
        raise argparse.ArgumentTypeError(f"{exc}: {expected}") from None


def payload_step(text: str) -> PayloadStep:
    """``KG@T``: a point mass [kg] picked up at time T [s]."""
    expected = f"KG@T: a mass in (0, {MAX_MASS:g}] kg and a time >= 0 s (e.g. 2@5), got {_shown(text)}"
    mass, at, time = text.partition("@")
    if not at:
        raise argparse.ArgumentTypeError(f"expected {expected}")
    try:
        value, when = finite(mass), finite(time)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected {expected}") from None
    if not (0 < value <= MAX_MASS and when >= 0):
        raise argparse.ArgumentTypeError(f"expected {expected}")
    return PayloadStep(value, when)


def sensor_noise(text: str) -> tuple[float, float, float]:
    """``SIGMA_Q[,SIGMA_V[,SIGMA_F]]`` [rad, rad/s, N] (σ_v, σ_F default 0; σ_F: the force sensor's,
    with a scene)."""
    expected = (
        f"SIGMA_Q[,SIGMA_V[,SIGMA_F]]: standard deviations >= 0 in rad, rad/s and N, got {_shown(text)}"
    )
    parts = text.split(",")
    if len(parts) not in (1, 2, 3):
        raise argparse.ArgumentTypeError(f"expected {expected}")
    try:
        values = [finite(x) for x in parts]
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected {expected}") from None
    if any(not 0 <= x <= 1e3 for x in values):
        raise argparse.ArgumentTypeError(f"expected {expected} (at most 1000)")
    values += [0.0] * (3 - len(values))
    return values[0], values[1], values[2]


def scale_range(text: str) -> tuple[float, float]:
    """``LO:HI``: the range a sweep draws each run's factor on ``--wrench`` from."""
    expected = f"LO:HI: finite factors with LO <= HI (e.g. 0:2), got {_shown(text)}"
    low, colon, high = text.partition(":")
    if not colon:
        raise argparse.ArgumentTypeError(f"expected {expected}")
    try:
        lo, hi = finite(low), finite(high)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected {expected}") from None
    if lo > hi or max(abs(lo), abs(hi)) > MAX_FORCE:
        raise argparse.ArgumentTypeError(f"expected {expected}")
    return lo, hi


def add_disturbance_options(p: argparse.ArgumentParser) -> None:
    """The plant's events, on a command that simulates (in its run options)."""
    group = run_group(p)
    group.add_argument(
        "--wrench",
        type=wrench,
        metavar="FX,FY,FZ[,MX,MY,MZ]@T0:T1",
        help="external force [N] (and moment [N·m]) on the end effector, world axes, from T0 to T1 [s]",
    )
    group.add_argument(
        "--payload-step",
        type=payload_step,
        metavar="KG@T",
        help="a point mass [kg] picked up at the end effector at time T [s] (the law is not told)",
    )
    group.add_argument(
        "--sensor-noise",
        type=sensor_noise,
        metavar="SIGMA_Q[,SIGMA_V[,SIGMA_F]]",
        help="Gaussian noise [rad, rad/s] on the q and q̇ the law measures, and [N] on the force its "
        "sensor reads with a scene (seeded: --noise-seed)",
    )
    group.add_argument(
        "--noise-seed",
        type=whole(0, 2**63 - 1),
        default=None,
        help="seed of the sensor noise (default 0; only with --sensor-noise)",
    )
    group.add_argument(
        "--delay",
        type=whole(0, MAX_DELAY),
        default=0,
        metavar="STEPS",
        help="steps between a measurement and the torque it produces (default 0)",
    )
    add_contact_options(p)  # the world the arm touches: a run option beside the events


def plant_events(args: Any) -> dict[str, Any]:
    """The plant's events the arguments ask for, as :class:`~twolink_pin.run_spec.PlantOptions`
    fields (none for a command without these options)."""
    from twolink_pin.disturbances import SensorNoise

    noise = getattr(args, "sensor_noise", None)
    seed = getattr(args, "noise_seed", None)
    if noise is None and seed is not None:
        raise InvalidParameterError(
            "--noise-seed",
            seed,
            "--sensor-noise SIGMA_Q[,SIGMA_V] with it (without noise a seed does nothing)",
        )
    return {
        "wrench": getattr(args, "wrench", None),
        "payload_step": getattr(args, "payload_step", None),
        "sensor_noise": None
        if noise is None
        else SensorNoise(noise[0], noise[1], seed=seed or 0, sigma_f=noise[2]),
        "delay": getattr(args, "delay", 0) or 0,
        **scene_of(args),
    }
