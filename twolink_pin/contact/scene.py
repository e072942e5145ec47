"""A scene: the surfaces the arm may touch and their contact properties — plain, frozen data.

A :class:`Scene` sits beside the plant's other options (:class:`~twolink_pin.plant_options.PlantOptions`,
``--scene FILE`` or ``--wall …``) and is read once; each plant computes its own contact from it
(the Pinocchio plant: :mod:`twolink_pin.contact.compliant`; a MuJoCo plant: MuJoCo's contacts
with a geom built from the same data).

**Surfaces.** A :class:`Surface` is a plane through ``point`` [m] with the unit outward
``normal`` (pointing to the side the arm is on), or with ``size`` the top face of a box of
``(length, width, depth)`` [m] centred on ``point`` (its in-plane axes :meth:`Surface.axes`): the
arm then touches it only where its contact point is over the face and less than ``depth`` inside.
The box's sides and edges are not surfaces (a contact point that leaves the face by its side is
free).

**Contact properties** (per surface, SI): ``stiffness`` k [N/m] and ``damping`` b [N·s/m] of the
normal force ``λ = max(0, k δ + b δ̇)`` at a penetration δ [m], and Coulomb's ``friction`` μ
(dimensionless). MuJoCo describes a soft contact by ``solref``/``solimp`` instead; a surface may
carry them (MuJoCo's own meaning, read by a MuJoCo plant only; the Pinocchio plant reads k, b, μ):
``solref`` = (timeconst [s], dampratio) or MuJoCo's direct form (−stiffness, −damping), ``solimp`` =
(dmin, dmax, width [m], midpoint, power).

**The arm's contact point** is a sphere of ``radius`` [m] (default :data:`DEFAULT_RADIUS`) centred
on the origin of ``frame`` (default: the robot's end effector, ``robot.ee_frame_id``). No other link
collides: a forearm through the wall goes unnoticed (the docs say so).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InputFileError, InvalidParameterError

DEFAULT_RADIUS = 0.02
"""Radius [m] of the contact sphere at the end effector: a 4-cm ball tip."""
DEFAULT_STIFFNESS = 1e4
"""k [N/m] of a surface that gives none (``--wall`` without one): 1 cm of penetration per 100 N."""
DEFAULT_DAMPING = 100.0
"""b [N·s/m] of a surface that gives none (about half-critical on a 1-kg end effector at k = 10⁴)."""
DEFAULT_SLIP_VELOCITY = 0.01
"""ε [m/s] of the regularised Coulomb friction ``−μ λ v_t / sqrt(|v_t|² + ε²)`` (below about ε a
contact creeps instead of sticking)."""
MAX_POSITION = 100.0
"""Largest coordinate [m] of a surface's point, and largest size."""
MAX_STIFFNESS = 1e9
"""Largest stiffness [N/m] (and damping [N·s/m]) accepted: beyond, no step is small enough."""
MAX_FRICTION = 10.0
"""Largest Coulomb coefficient accepted."""
MAX_SURFACES = 16
"""Most surfaces in one scene."""
MAX_SCENE_BYTES = 1 << 20
"""Largest scene file read (1 MiB)."""
SCENE_KEYS = frozenset({"radius", "frame", "slip_velocity", "surface"})
"""Keys of a scene file's top level."""
SURFACE_KEYS = frozenset(
    {"name", "point", "normal", "stiffness", "damping", "friction", "size", "solref", "solimp"}
)
"""Keys of a scene file's ``[[surface]]`` table."""


def _number(
    name: str, value: Any, expected: str, low: float, high: float, *, open_low: bool = False
) -> float:
    """``value`` as a float in ``[low, high]`` (``(low, high]`` with ``open_low``), else an error
    naming ``name`` and ``expected``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidParameterError(name, value, expected)
    x = float(value)
    if not math.isfinite(x) or x > high or x < low or (open_low and x == low):
        raise InvalidParameterError(name, value, expected)
    return x


def _vector(
    name: str, value: Any, size: int, expected: str, bound: float = MAX_POSITION
) -> tuple[float, ...]:
    """``value`` as ``size`` finite floats within ±``bound``."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != size:
        raise InvalidParameterError(name, value, expected)
    out = []
    for x in value:
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or abs(x) > bound:
            raise InvalidParameterError(name, list(value), expected)
        out.append(float(x))
    return tuple(out)


@dataclass(frozen=True)
class Surface:
    """One surface of a scene (see the module docstring).

    Attributes:
        point: A point of the plane [m], world coordinates (a box face's centre).
        normal: The outward normal (towards the arm's side), world axes; normalised here.
        stiffness: k [N/m], > 0.
        damping: b [N·s/m], >= 0.
        friction: Coulomb's μ, >= 0 (0: frictionless).
        name: The surface's name in messages and tables.
        size: ``(length, width, depth)`` [m] of the box whose top face the surface is, along
            :meth:`axes`; None: an unbounded plane.
        solref: MuJoCo's ``solref`` (2 numbers), read by a MuJoCo plant only; None: derived there.
        solimp: MuJoCo's ``solimp`` (5 numbers), read by a MuJoCo plant only; None: derived there.
    """

    point: tuple[float, ...]
    normal: tuple[float, ...]
    stiffness: float = DEFAULT_STIFFNESS
    damping: float = DEFAULT_DAMPING
    friction: float = 0.0
    name: str = "wall"
    size: tuple[float, ...] | None = None
    solref: tuple[float, ...] | None = None
    solimp: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        label = f"surface {self.name!r}" if isinstance(self.name, str) else "surface"
        if not isinstance(self.name, str) or not self.name.strip() or len(self.name) > 64:
            raise InvalidParameterError(f"{label}: name", self.name, "a name of 1 to 64 characters")
        point = _vector(
            f"{label}: point", self.point, 3, f"3 finite coordinates [m] within ±{MAX_POSITION:g}"
        )
        normal = _vector(f"{label}: normal", self.normal, 3, "3 finite numbers: the outward normal", math.inf)
        length = math.sqrt(sum(x * x for x in normal))
        if not (math.isfinite(length) and length > 1e-9):
            raise InvalidParameterError(
                f"{label}: normal", list(normal), "a non-zero direction (the outward normal, towards the arm)"
            )
        object.__setattr__(self, "point", point)
        object.__setattr__(self, "normal", tuple(x / length for x in normal))
        stiffness = _number(
            f"{label}: stiffness",
            self.stiffness,
            f"a stiffness in (0, {MAX_STIFFNESS:g}] N/m",
            0.0,
            MAX_STIFFNESS,
            open_low=True,
        )
        damping = _number(
            f"{label}: damping",
            self.damping,
            f"a damping in [0, {MAX_STIFFNESS:g}] N·s/m",
            0.0,
            MAX_STIFFNESS,
        )
        friction = _number(
            f"{label}: friction",
            self.friction,
            f"a Coulomb coefficient μ in [0, {MAX_FRICTION:g}]",
            0.0,
            MAX_FRICTION,
        )
        object.__setattr__(self, "stiffness", stiffness)
        object.__setattr__(self, "damping", damping)
        object.__setattr__(self, "friction", friction)
        if self.size is not None:
            size = _vector(f"{label}: size", self.size, 3, "(length, width, depth) [m], each > 0")
            if min(size) <= 0:
                raise InvalidParameterError(
                    f"{label}: size", list(size), "(length, width, depth) [m], each > 0"
                )
            object.__setattr__(self, "size", size)
        self._check_mujoco(label)

    def _check_mujoco(self, label: str) -> None:
        """``solref``: 2 numbers, both > 0 (timeconst [s], dampratio) or both <= 0 with the first
        < 0 (−stiffness, −damping); ``solimp``: 0 < dmin <= dmax < 1, width > 0 [m],
        0 < midpoint < 1, power >= 1."""
        if self.solref is not None:
            ref = _vector(f"{label}: solref", self.solref, 2, "MuJoCo's solref: 2 finite numbers", math.inf)
            if not ((ref[0] > 0 and ref[1] > 0) or (ref[0] < 0 and ref[1] <= 0)):
                raise InvalidParameterError(
                    f"{label}: solref",
                    list(ref),
                    "(timeconst > 0 s, dampratio > 0) or MuJoCo's direct (−stiffness < 0, −damping <= 0)",
                )
            object.__setattr__(self, "solref", ref)
        if self.solimp is not None:
            imp = _vector(f"{label}: solimp", self.solimp, 5, "MuJoCo's solimp: 5 finite numbers", math.inf)
            dmin, dmax, width, midpoint, power = imp
            if not (0 < dmin <= dmax < 1 and width > 0 and 0 < midpoint < 1 and power >= 1):
                raise InvalidParameterError(
                    f"{label}: solimp",
                    list(imp),
                    "(dmin, dmax, width, midpoint, power) with 0 < dmin <= dmax < 1, width > 0 m, "
                    "0 < midpoint < 1, power >= 1",
                )
            object.__setattr__(self, "solimp", imp)

    @property
    def unit_normal(self) -> np.ndarray:
        """``normal`` as an array (3,)."""
        return np.array(self.normal)

    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """The face's in-plane axes ``(u, w)`` (unit, with ``u × w = n``): ``u`` is the world axis
        least aligned with the normal (x before y before z on a tie), made perpendicular to it."""
        n = self.unit_normal
        e = np.eye(3)[int(np.argmin(np.abs(n)))]
        u = e - (e @ n) * n
        u /= np.linalg.norm(u)
        return u, np.cross(n, u)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance [m] of ``points`` (…, 3) from the plane, positive on the normal's side."""
        return (np.asarray(points, dtype=float) - np.array(self.point)) @ self.unit_normal

    def over_face(self, points: np.ndarray) -> np.ndarray:
        """Whether each of ``points`` (…, 3) projects onto the face and is less than ``depth``
        inside (all True for an unbounded plane)."""
        points = np.asarray(points, dtype=float)
        if self.size is None:
            return np.ones(points.shape[:-1], dtype=bool)
        u, w = self.axes()
        offset = points - np.array(self.point)
        length, width, depth = self.size
        return (
            (np.abs(offset @ u) <= length / 2)
            & (np.abs(offset @ w) <= width / 2)
            & (offset @ self.unit_normal > -depth)
        )

    def describe(self) -> str:
        """``wall (k = 1000 N/m, b = 20 N·s/m, μ = 0.2)``."""
        return (
            f"{self.name} (k = {self.stiffness:g} N/m, b = {self.damping:g} N·s/m"
            + (f", μ = {self.friction:g}" if self.friction else "")
            + ")"
        )


@dataclass(frozen=True)
class Scene:
    """The surfaces of a run's world and how the arm touches them (see the module docstring).

    Attributes:
        surfaces: One to :data:`MAX_SURFACES` surfaces, distinct names.
        radius: The contact sphere's radius [m] at ``frame``'s origin, >= 0.
        frame: The arm's frame that touches (None: the robot's end effector).
        slip_velocity: ε [m/s] of the regularised Coulomb friction, > 0.
    """

    surfaces: tuple[Surface, ...] = field(default=())
    radius: float = DEFAULT_RADIUS
    frame: str | None = None
    slip_velocity: float = DEFAULT_SLIP_VELOCITY

    def __post_init__(self) -> None:
        items = self.surfaces
        if isinstance(items, (Surface, Mapping)) or not isinstance(items, Sequence):
            items = (items,)  # type: ignore[assignment]
        surfaces = tuple(Surface(**dict(s)) if isinstance(s, Mapping) else s for s in items)
        if not 1 <= len(surfaces) <= MAX_SURFACES or not all(isinstance(s, Surface) for s in surfaces):
            raise InvalidParameterError(
                "scene.surfaces",
                f"{len(surfaces)} entries",
                f"1 to {MAX_SURFACES} surfaces (twolink_pin.contact.Surface)",
            )
        names = [s.name for s in surfaces]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise InvalidParameterError("scene.surfaces", twice[0], "each surface named once")
        object.__setattr__(self, "surfaces", surfaces)
        object.__setattr__(
            self, "radius", _number("scene.radius", self.radius, "a radius in [0, 1] m", 0.0, 1.0)
        )
        object.__setattr__(
            self,
            "slip_velocity",
            _number(
                "scene.slip_velocity",
                self.slip_velocity,
                "a velocity in (0, 10] m/s",
                0.0,
                10.0,
                open_low=True,
            ),
        )
        if self.frame is not None and not (isinstance(self.frame, str) and self.frame):
            raise InvalidParameterError("scene.frame", self.frame, "a frame name, or None (the end effector)")

    def index(self, name: str | None) -> int:
        """The index of surface ``name`` (None: the only surface).

        Raises:
            InvalidParameterError: no such surface, or None with several surfaces.
        """
        names = [s.name for s in self.surfaces]
        if name is None:
            if len(names) == 1:
                return 0
            raise InvalidParameterError("surface", None, f"the name of one of the scene's surfaces {names}")
        if name not in names:
            raise InvalidParameterError("surface", name, f"one of the scene's surfaces {names}")
        return names.index(name)

    def describe(self) -> str:
        """The surfaces in a few words (the plant's summary)."""
        return "contact with " + ", ".join(s.describe() for s in self.surfaces)


def read_scene(path: str | os.PathLike[str]) -> Scene:
    """The scene a TOML or JSON file describes::

        radius = 0.02              # m, the contact sphere at the end effector (optional)
        # frame = "ee_link"        # optional: the touching frame (default: the end effector)
        # slip_velocity = 0.01     # m/s, optional

        [[surface]]
        name = "wall"
        point = [0.55, 0.0, 0.0]   # m
        normal = [-1.0, 0.0, 0.0]  # outward: towards the arm
        stiffness = 1000.0         # N/m
        damping = 20.0             # N·s/m
        friction = 0.2             # Coulomb μ
        # size = [0.4, 0.3, 0.05]  # m: a box's top face (length, width, depth); default: a plane

    Raises:
        InputFileError: the file cannot be read or parsed.
        InvalidParameterError: a key or value is wrong (named with the file and the surface).
    """
    from twolink_pin.documents import load_json, load_toml
    from twolink_pin.files import read_input_file

    file = Path(os.fspath(path))
    data = read_input_file(file, MAX_SCENE_BYTES, "a scene file (.toml or .json)")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputFileError(
            str(file), f"is not UTF-8 (byte {err.start}); expected a UTF-8 text file"
        ) from None
    suffix = file.suffix.lower()
    if suffix not in (".toml", ".json"):
        raise InputFileError(str(file), f"has the suffix {suffix!r}; expected .toml or .json")
    document = load_toml(text, str(file)) if suffix == ".toml" else load_json(text, str(file))
    if not isinstance(document, dict):
        raise InputFileError(str(file), "expected a table (TOML) or an object (JSON) at the top level")
    unknown = sorted(set(document) - SCENE_KEYS)
    if unknown:
        raise InvalidParameterError(
            f"{file}: {unknown[0]}", document[unknown[0]], f"only the keys {sorted(SCENE_KEYS)}"
        )
    tables = document.get("surface")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise InvalidParameterError(f"{file}: surface", tables, "one or more [[surface]] tables")
    surfaces = []
    for i, table in enumerate(tables):
        extra = sorted(set(table) - SURFACE_KEYS)
        if extra:
            raise InvalidParameterError(
                f"{file}: surface[{i}].{extra[0]}", table[extra[0]], f"only the keys {sorted(SURFACE_KEYS)}"
            )
        for key in ("point", "normal"):
            if key not in table:
                raise InvalidParameterError(
                    f"{file}: surface[{i}].{key}", None, "3 numbers (point [m], normal)"
                )
        try:
            surfaces.append(Surface(**{"name": f"surface{i + 1}" if len(tables) > 1 else "wall", **table}))
        except InvalidParameterError as err:
            raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None
    options = {key: document[key] for key in ("radius", "frame", "slip_velocity") if key in document}
    try:
        return Scene(tuple(surfaces), **options)
    except InvalidParameterError as err:
        raise InvalidParameterError(f"{file}: {err.name}", err.value, err.expected) from None


__all__ = [
    "DEFAULT_DAMPING",
    "DEFAULT_RADIUS",
    "DEFAULT_SLIP_VELOCITY",
    "DEFAULT_STIFFNESS",
    "Scene",
    "Surface",
    "read_scene",
]
