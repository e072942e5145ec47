"""A robot profile as a TOML file: any URDF, one arm of it, its home and defaults.

One way to describe an arm, for the catalog's robots (``robots/*.toml`` in the package) as for
a user's (``--robot FILE.toml`` on every command; ``twolink-pin robots`` lists those of the
folder :func:`user_folder` names)::

    description = "Baxter's right arm, the rest locked"
    urdf = "example-robot-data:baxter_description/urdf/baxter.urdf"   # or a path, or a catalog name
    end_effector = "right_hand"
    home = [0.0, -0.55, 0.0, 0.75, 0.0, 1.26, 0.0]     # rad (m for a prismatic joint), per free joint
    amplitude = 0.3                                     # rad: the default reference's swing about home

    [locked]                                            # or: locked = ["head_pan", ...] (at 0)
    head_pan = 0.0

    [gains.pd]                                          # preset gains per law, as --gain takes them
    kp = [300, 300, 200, 200, 50, 50, 20]

Keys (every one optional but ``urdf``): ``name`` (default: the file's stem), ``description``,
``urdf`` (a path relative to the file, a catalog robot's name — its URDF, not its profile —, or
``example-robot-data:PATH`` below that package's ``robots`` folder), ``end_effector`` (a frame),
``locked`` (joint names held at 0 clipped to their limits, or a table name → position [rad or
m]), ``free`` (the joints left free, every other one locked — at its ``locked`` position if
given, else 0 clipped to its limits: one arm of a tree in one line), ``home`` (one value per joint left free), ``amplitude`` [rad], ``q0_offset`` [rad, per
joint], ``acceleration_limits`` [rad/s², per joint], ``repair_inertias`` (bool),
``friction = {viscous = [...], coulomb = [...]}`` [N·m·s/rad, N·m], ``trajectory = {times =
[...], joint_points = [[...], ...]}`` or ``cartesian_points`` (with ``branch``, ``period``),
``[gains.LAW]`` tables, and ``effects = {armature = [...], damping = [...], frictionloss = [...],
source = "..."}`` [kg·m², N·m·s/rad, N·m per joint] (the arm's effects a plant models on
request: ``--armature arm``). An unknown key, a value of the wrong kind, and — when the robot is
loaded — a joint or frame the URDF lacks, a lock of every joint, a home outside the ranges or a
``gains`` table of an unknown law are refused in one line naming the key and the file.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import tomllib

from twolink_pin.errors import InvalidParameterError, InvalidURDFError
from twolink_pin.files import read_input_file
from twolink_pin.model.profile import ArmEffects, RobotProfile, TrajectorySpec
from twolink_pin.model.registry import CATALOG
from twolink_pin.model.robot_data import example_robot_urdf, share_folder

PROFILE_SUFFIX = ".toml"
"""What a profile file's name ends with (``--robot FILE.toml``)."""
MAX_PROFILE_BYTES = 1 << 20
"""Largest profile file read (1 MiB)."""
USER_FOLDER_VARIABLE = "TWOLINK_PIN_ROBOTS"
"""The environment variable naming the folder of a user's profiles."""
EXAMPLE_ROBOT_DATA = "example-robot-data:"
"""The prefix of a URDF given below example-robot-data's ``robots`` folder."""
KEYS = frozenset(
    {
        "name",
        "description",
        "urdf",
        "end_effector",
        "locked",
        "free",
        "home",
        "amplitude",
        "q0_offset",
        "acceleration_limits",
        "repair_inertias",
        "friction",
        "trajectory",
        "gains",
        "effects",
    }
)
"""The keys a profile file may have."""


def user_folder() -> Path:
    """The folder of a user's profiles: ``$TWOLINK_PIN_ROBOTS``, else
    ``$XDG_CONFIG_HOME/twolink-pin/robots`` (``~/.config/twolink-pin/robots``)."""
    given = os.environ.get(USER_FOLDER_VARIABLE)
    if given:
        return Path(given).expanduser()
    config = os.environ.get("XDG_CONFIG_HOME") or str(Path("~/.config").expanduser())
    return Path(config) / "twolink-pin" / "robots"


def is_profile_path(text: str) -> bool:
    """Whether ``--robot TEXT`` names a profile file."""
    return text.lower().endswith(PROFILE_SUFFIX)


class _Reader:
    """Reads one file's keys, each refusal naming ``FILE: key``."""

    def __init__(self, path: Path, data: Mapping[str, Any]) -> None:
        self.path, self.data = path, data

    def fail(self, key: str, value: Any, expected: str) -> InvalidParameterError:
        return InvalidParameterError(f"{self.path}: {key}", value, expected)

    def text(self, key: str) -> str | None:
        value = self.data.get(key)
        if value is not None and (not isinstance(value, str) or not value.strip()):
            raise self.fail(key, value, "a non-empty string")
        return value

    def numbers(self, key: str, value: Any = None, unit: str = "") -> tuple[float, ...] | None:
        value = self.data.get(key) if value is None else value
        if value is None:
            return None
        if not isinstance(value, list) or not value or not all(_is_number(x) for x in value):
            raise self.fail(key, value, f"a non-empty list of finite numbers{unit}")
        return tuple(float(x) for x in value)

    def number(self, key: str, positive: bool = True) -> float | None:
        value = self.data.get(key)
        if value is None:
            return None
        if not _is_number(value) or (positive and not value > 0):
            raise self.fail(key, value, "a finite number > 0" if positive else "a finite number")
        return float(value)


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _urdf(reader: _Reader) -> tuple[Path, tuple[Path, ...]]:
    """The URDF the file names and the folders its ``package://`` meshes resolve from."""
    text = reader.text("urdf")
    if text is None:
        raise reader.fail("urdf", None, "the robot's URDF: a path, a catalog name or example-robot-data:PATH")
    if text.startswith(EXAMPLE_ROBOT_DATA):
        path = example_robot_urdf(text.removeprefix(EXAMPLE_ROBOT_DATA))
        return path, (share_folder(path),)
    if text in CATALOG:
        path, profile = CATALOG[text]()
        return path, profile.package_dirs
    path = Path(text).expanduser()
    path = path if path.is_absolute() else reader.path.parent / path
    if not path.is_file():
        raise reader.fail(
            "urdf",
            text,
            f"an existing URDF file (relative to {reader.path.parent}), a catalog name or "
            f"example-robot-data:PATH; no file {path}",
        )
    return path, (path.parent,)


def _locked(reader: _Reader) -> tuple[tuple[str, ...], tuple[float, ...] | None]:
    value = reader.data.get("locked")
    if value is None:
        return (), None
    if isinstance(value, list) and all(isinstance(x, str) and x for x in value):
        return tuple(value), None
    if isinstance(value, dict) and value and all(_is_number(x) for x in value.values()):
        return tuple(value), tuple(float(x) for x in value.values())
    raise reader.fail("locked", value, "a list of joint names, or a table joint name → position [rad or m]")


def _gains(reader: _Reader) -> Mapping[str, Mapping[str, Any]]:
    value = reader.data.get("gains", {})
    if not isinstance(value, dict) or not all(isinstance(v, dict) for v in value.values()):
        raise reader.fail("gains", value, "tables [gains.LAW] of gain name = value")
    presets = {}
    for law, table in value.items():
        for name, gain in table.items():
            ok = _is_number(gain) or (isinstance(gain, list) and gain and all(_is_number(x) for x in gain))
            if not ok:
                raise reader.fail(
                    f"gains.{law}.{name}", gain, "a number or a list of numbers (as --gain takes them)"
                )
        presets[law] = MappingProxyType(
            {k: tuple(v) if isinstance(v, list) else float(v) for k, v in table.items()}
        )
    return MappingProxyType(presets)


def _friction(reader: _Reader) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    value = reader.data.get("friction")
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) != {"viscous", "coulomb"}:
        raise reader.fail(
            "friction", value, "a table {viscous = [N·m·s/rad per joint], coulomb = [N·m per joint]}"
        )
    viscous = reader.numbers("friction.viscous", value["viscous"], " [N·m·s/rad]")
    coulomb = reader.numbers("friction.coulomb", value["coulomb"], " [N·m]")
    assert viscous is not None and coulomb is not None
    return viscous, coulomb


def _effects(reader: _Reader) -> ArmEffects | None:
    """What the real arm adds to its rigid bodies, per joint, with its source (``--armature arm``)."""
    value = reader.data.get("effects")
    if value is None:
        return None
    units = {"armature": " [kg·m²]", "damping": " [N·m·s/rad]", "frictionloss": " [N·m]"}
    if not isinstance(value, dict) or not value or not set(value) <= {*units, "source"}:
        raise reader.fail(
            "effects",
            value,
            "a table {armature = [kg·m²], damping = [N·m·s/rad], frictionloss = [N·m], source = '...'}",
        )
    source = value.get("source", "")
    if not isinstance(source, str):
        raise reader.fail("effects.source", source, "a string citing where the values come from")
    given = {}
    for key, unit in units.items():
        if key in value:
            numbers = reader.numbers(f"effects.{key}", value[key], f" >= 0{unit}")
            assert numbers is not None
            if not all(x >= 0 for x in numbers):
                raise reader.fail(
                    f"effects.{key}", value[key], f"a non-empty list of finite numbers >= 0{unit}"
                )
            given[key] = numbers
    return ArmEffects(**given, source=source)


def _trajectory(reader: _Reader) -> TrajectorySpec | None:
    value = reader.data.get("trajectory")
    if value is None:
        return None
    allowed = {"times", "joint_points", "cartesian_points", "branch", "period"}
    if not isinstance(value, dict) or not set(value) <= allowed or "times" not in value:
        raise reader.fail(
            "trajectory", value, f"a table of {sorted(allowed)} with times and one kind of points"
        )
    times = reader.numbers("trajectory.times", value["times"], " [s]")
    points = {}
    for kind in ("joint_points", "cartesian_points"):
        if kind in value:
            rows = value[kind]
            if not isinstance(rows, list) or not rows or not all(isinstance(r, list) for r in rows):
                raise reader.fail(f"trajectory.{kind}", rows, "a list of points (lists of numbers)")
            points[kind] = tuple(reader.numbers(f"trajectory.{kind}", r) or () for r in rows)
    if len(points) != 1:
        raise reader.fail("trajectory", value, "exactly one of joint_points and cartesian_points")
    branch = value.get("branch", 0)
    if branch not in (0, 1):
        raise reader.fail("trajectory.branch", branch, "0 or 1")
    period = value.get("period")
    if period is not None and not (_is_number(period) and period > 0):
        raise reader.fail("trajectory.period", period, "a period > 0 s")
    assert times is not None
    return TrajectorySpec(times=times, branch=int(branch), period=period, **points)


def read_profile_file(path: str | os.PathLike[str], name: str | None = None) -> tuple[Path, RobotProfile]:
    """The URDF and profile a profile file describes (module docstring); ``name``: the profile's
    name when the file gives none (default: the file's stem).

    Raises:
        InvalidURDFError: the file cannot be read or is not TOML.
        InvalidParameterError: an unknown key or a value of the wrong kind, named ``FILE: key``.
    """
    file = Path(os.fspath(path))
    try:
        raw = read_input_file(str(file), MAX_PROFILE_BYTES, "a robot profile (TOML)")
        data = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise InvalidURDFError(
            str(file), "profile", f"not a TOML file ({exc}); expected a robot profile"
        ) from None
    except Exception as exc:  # InputFileError: missing, a directory, too large
        raise InvalidURDFError(str(file), "profile", getattr(exc, "reason", str(exc))) from None
    reader = _Reader(file, data)
    unknown = sorted(set(data) - KEYS)
    if unknown:
        raise reader.fail(unknown[0], data[unknown[0]], f"one of the profile keys {', '.join(sorted(KEYS))}")
    urdf, package_dirs = _urdf(reader)
    locked, positions = _locked(reader)
    free = data.get("free")
    if free is not None:
        if not isinstance(free, list) or not free or not all(isinstance(x, str) and x for x in free):
            raise reader.fail("free", free, "a non-empty list of joint names (every other joint is locked)")
    repair = data.get("repair_inertias", False)
    if not isinstance(repair, bool):
        raise reader.fail("repair_inertias", repair, "true or false")
    profile = RobotProfile(
        name=reader.text("name") or name or file.stem,
        description=reader.text("description") or f"profile {file}",
        gain_presets=_gains(reader),
        friction=_friction(reader),
        q0_offset=reader.numbers("q0_offset", unit=" [rad]"),
        trajectory=_trajectory(reader),
        ee_frame=reader.text("end_effector"),
        package_dirs=package_dirs,
        source=str(file),
        locked_joints=locked,
        locked_positions=positions,
        free_joints=None if free is None else tuple(free),
        home=reader.numbers("home", unit=" [rad or m]"),
        acceleration_limits=reader.numbers("acceleration_limits", unit=" [rad/s²]"),
        amplitude=reader.number("amplitude"),
        repair_inertias=repair,
        effects=_effects(reader),
        file=file,
    )
    return urdf, profile
