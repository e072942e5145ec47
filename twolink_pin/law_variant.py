"""One law with other settings: a **variant**, ``LAW@KEY=VALUE[@KEY=VALUE…]``.

``compare pd pd@kp=200,150`` runs ``pd`` twice, once with its defaults and once with
``kp = (200, 150)`` N·m/rad; ``compare computed-torque computed-torque@model=identified.urdf``
runs the law once on the robot's own model and once believing the file's inertias. Each
variant is a row of its own, named by its text (:attr:`Variant.key`).

* ``LAW`` is what a command takes as a law: a registered name, ``path/to/file.py:Class`` or
  ``package.module:Class``.
* ``KEY`` is a gain of the law (``kp``, ``lam``, …: its ``Gains`` fields), ``model``, ``p0``, or
  a plant key (:data:`~twolink_pin.arm_effects.PLANT_KEYS`: ``plant``, ``armature``,
  ``joint_damping``, ``frictionloss``, ``soft_limits``, ``solref``, ``solimp``, ``integrator``,
  ``saturate``): ``pd@plant=mujoco`` runs ``pd`` on the MuJoCo plant beside ``pd`` on
  Pinocchio's, ``pd@plant=mujoco@armature=arm`` with the arm's armature.
* ``VALUE`` is written as the single-law options take it: a gain as ``--gain NAME=V`` does
  (one number, or comma-separated numbers: per joint, or a matrix row by row;
  :func:`gain_value`), ``model=FILE`` as ``--model FILE`` (identified parameters or a URDF
  whose inertias the law believes), ``p0=FILE`` as ``--p0 FILE`` (where the estimates of a
  law that estimates start); a plant key as its option does (``plant=mujoco``,
  ``armature=arm`` or ``armature=0.1,0.2``, ``soft_limits=off``, ``integrator=implicitfast``).

**Where a setting starts.** An ``@`` starts a setting only when a key and ``=`` follow it
(``@kp=``, ``@model=``): a law file's path or a parameter file's path may hold ``@`` and ``:``
anywhere else (``~/runs@2/law.py:MyLaw@k=3``, ``pd@model=C:/id@v2.urdf``); a path that holds
``@NAME=`` itself cannot be written in a variant (rename it). ``:`` plays no part in the
split, so ``file.py:Class`` and a Windows drive are read as the law commands read them.

A variant's settings replace the command's own for its row (``--gain LAW.NAME``,
``--lambda``, ``--model``, ``--p0``); the run is then built by the one builder,
:meth:`RunSpec.for_law <twolink_pin.run_spec.RunSpec.for_law>` and
:meth:`~twolink_pin.run_spec.RunSpec.build`. :func:`format_variant` writes a run's settings
back as a variant (``tune`` names a kept run with it); :func:`parse_variant` reads it back
to the same values.
"""

from __future__ import annotations

import hashlib
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin.arm_effects import PLANT_KEYS, plant_value
from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import spec_of
from twolink_pin.errors import InvalidParameterError
from twolink_pin.scenario import law_class

PARAMETER_KEYS = ("model", "p0")
"""The keys that are no gain: the parameter file the law's model believes (``model``, as
``--model``) or its estimates start at (``p0``, as ``--p0``)."""
SETTING = re.compile(r"@(?=[A-Za-z_][A-Za-z0-9_]*=)")
"""An ``@`` that starts a setting: a key (a name) and ``=`` follow it."""
GainValue = float | tuple[float, ...] | str
"""A gain as the command line gives it: one number or several (per joint, a matrix row by row),
or a word (a gain of choices, ``on_infeasible=fail``)."""
WORD = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
"""A gain's value that is a word, not a number (``relax``): the gain's own check decides."""


def gain_value(name: str, text: str, choices: tuple[str, ...] | None = None) -> GainValue:
    """``text`` read as ``--gain NAME=TEXT`` reads it: one finite number (``200``, ``1e-3``)
    or comma-separated finite numbers (``30,40``; a matrix row by row), as floats; or one word
    (``fail``: a gain of choices), as text. ``choices``: the gain's words when the law is known
    (``()`` for a gain of numbers: a word is then refused here); None: a word is kept for the
    gain's own check (:class:`~twolink_pin.controllers.Gains`) to judge.

    Raises:
        InvalidParameterError: an empty entry, text that is no number, or a non-finite one
            (named ``--gain NAME``, with the text received).
    """
    word = text.strip()
    if WORD.fullmatch(word) and word.lower() not in ("nan", "inf", "infinity"):
        if choices is None or word in choices:
            return word
        if choices:
            raise InvalidParameterError(f"--gain {name}", text, f"one of {', '.join(map(repr, choices))}")
    numbers = []
    for entry in text.split(","):
        try:
            value = float(entry)
        except ValueError:
            raise InvalidParameterError(f"--gain {name}", text, f"a number, got {_shown(entry)}") from None
        if not math.isfinite(value):
            raise InvalidParameterError(f"--gain {name}", text, f"a finite number, got {_shown(entry)}")
        numbers.append(value)
    return numbers[0] if len(numbers) == 1 else tuple(numbers)


def _shown(text: str, limit: int = 200) -> str:
    return repr(text if len(text) <= limit else text[:limit] + "…")


@dataclass(frozen=True)
class Variant:
    """A law and the settings of one run of it (see the module docstring).

    Attributes:
        text: The variant as written (``pd@kp=200,150``).
        law: The law as a command takes it (``pd``, ``path/to/file.py:Class``).
        name: The law's registered name (its class's ``name``).
        gains: The gains it sets, ``((name, value), ...)`` in the order written.
        parameters: The parameter file of ``model=`` or ``p0=``, or None.
        parameters_use: ``"model"``, ``"p0"``, or ``""`` without a file.
        plant: The plant options it sets, ``((PlantOptions field, value), ...)``
            (:data:`~twolink_pin.arm_effects.PLANT_KEYS`).
    """

    text: str
    law: str
    name: str
    gains: tuple[tuple[str, GainValue], ...] = ()
    parameters: str | None = None
    parameters_use: str = ""
    plant: tuple[tuple[str, Any], ...] = ()

    @property
    def key(self) -> str:
        """The row's name: the law's registered name and the settings as written
        (``pd@kp=200,150``; ``sliding-mode@k=3`` for ``examples/sliding_mode.py:SlidingMode@k=3``).
        A law without settings is its name, as before variants."""
        return self.name + self.text[len(self.law) :]

    @property
    def settings(self) -> tuple[tuple[str, Any], ...]:
        """Every setting, gains and the parameter file, as ``((key, value), ...)``."""
        extra = () if self.parameters is None else ((self.parameters_use, self.parameters),)
        return (*self.gains, *extra, *self.plant)

    def law_class(self) -> type[Controller]:
        """The law's class."""
        return law_class(self.law)

    def same_run(self, other: Variant) -> bool:
        """Whether ``other`` names the same law with the same settings (in any order)."""
        if self.law_class() is not other.law_class():
            return False
        mine, theirs = dict(self.settings), dict(other.settings)
        return mine.keys() == theirs.keys() and all(_equal(mine[k], theirs[k]) for k in mine)


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    return bool(np.array_equal(np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))))


def split_variant(text: str) -> tuple[str, list[tuple[str, str]]]:
    """``(law, [(key, value text), ...])`` of ``text``, syntax only (no law is loaded).

    Raises:
        InvalidParameterError: no law before the first setting, an ``@`` with no ``KEY=``
            after it.
    """
    if not isinstance(text, str) or not text.strip():
        raise InvalidParameterError(
            "CONTROLLER", text, "a law: a name, path/to/file.py:Class or module:Class"
        )
    parts = SETTING.split(text)
    law, settings = parts[0], parts[1:]
    example = "e.g. pd@kp=200 or computed-torque@model=identified.urdf"
    if not law:
        raise InvalidParameterError(
            f"variant {_shown(text)}", text, f"a law before the first '@' ({example})"
        )
    stray = law.rpartition(":")[2]  # a registered name, or the class of file.py:Class / module:Class
    if "@" in stray:
        bad = stray[stray.index("@") :]
        what = "nothing follows it" if bad == "@" else f"{bad[1:]!r} is no KEY=VALUE"
        raise InvalidParameterError(
            f"variant {_shown(text)}", bad, f"KEY=VALUE after each '@' ({what}; {example})"
        )
    return law, [(key, value) for key, _, value in (s.partition("=") for s in settings)]


def parse_variant(text: str) -> Variant:
    """The variant ``text`` names, its law loaded and every setting checked: a known key
    (the law's gains, ``model``, ``p0``), given once, with a value (see the module docstring).

    Raises:
        InvalidParameterError: the bad key or value, named with the variant and what was
            expected (the law's gains for an unknown key).
        ControllerSpecError: no such law.
    """
    law, pairs = split_variant(text)
    cls = law_class(law)
    keys = (*cls.Gains.field_names(), *PARAMETER_KEYS, *PLANT_KEYS)
    where = f"variant {_shown(text)}"
    gains: dict[str, GainValue] = {}
    files: dict[str, str] = {}
    plant: dict[str, Any] = {}
    seen: dict[str, str] = {}
    for key, value in pairs:
        if key not in keys:
            raise InvalidParameterError(
                f"{where}: key",
                key,
                f"a gain of '{cls.name}' ({', '.join(cls.Gains.field_names())}), model, p0 or a plant key "
                f"({', '.join(PLANT_KEYS)})",
            )
        if key in seen:
            raise InvalidParameterError(
                f"{where}: {key}", value, f"each key once ({key} is given twice: {seen[key]!r} and {value!r})"
            )
        seen[key] = value
        if not value.strip():
            raise InvalidParameterError(
                f"{where}: {key}", value, f"a value after '{key}=' (e.g. {cls.name}@{_example(key)})"
            )
        if key in PARAMETER_KEYS:
            files[key] = value
            continue
        if key in PLANT_KEYS and key not in cls.Gains.field_names():
            try:
                plant[PLANT_KEYS[key]] = plant_value(key, value)
            except InvalidParameterError as exc:
                raise InvalidParameterError(f"{where}: {key}", value, exc.expected) from None
            continue
        try:
            gains[key] = gain_value(key, value, spec_of(cls.Gains, key).choices)
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"{where}: {key}", value, exc.expected) from None
    if len(files) > 1:
        raise InvalidParameterError(
            where, "model and p0", "one parameter file per run: model=FILE or p0=FILE (as --model or --p0)"
        )
    use, path = next(iter(files.items()), ("", None))
    if use == "p0" and not cls.estimates:
        raise InvalidParameterError(
            f"{where}: p0",
            path,
            f"a law that estimates parameters ('{cls.name}' estimates none; model=FILE "
            "is the file its model believes)",
        )
    return Variant(text, law, cls.name, tuple(gains.items()), path, use, tuple(plant.items()))


def _example(key: str) -> str:
    examples = {"model": "model=identified.urdf", "p0": "p0=identified.json", "plant": "plant=mujoco"}
    return examples.get(key, f"{key}=200")


def parse_variants(texts: Sequence[str]) -> tuple[Variant, ...]:
    """Every variant of ``texts`` (:func:`parse_variant`), each a row of its own.

    Raises:
        InvalidParameterError: the same variant twice (the same law with the same settings,
            in any order), or two that would be rows of the same name.
    """
    variants: list[Variant] = []
    for text in texts:
        variant = parse_variant(text)
        for earlier in variants:
            if variant.same_run(earlier) or variant.key == earlier.key:
                same = "the same run as" if variant.same_run(earlier) else "a row of the same name as"
                raise InvalidParameterError(
                    "CONTROLLER",
                    text,
                    f"each variant once: it is {same} {earlier.text!r} (give it other settings, e.g. "
                    f"{variant.name}@{_example(variant.law_class().Gains.field_names()[0])})",
                )
        variants.append(variant)
    return tuple(variants)


def _number(x: float) -> str:
    """``x`` as the shortest text that reads back to the same float (``200``, ``0.1``, ``1e-300``)."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


def _value_text(name: str, value: Any) -> str:
    """A gain value as ``--gain NAME=`` takes it: numbers comma-separated (a matrix row by row),
    or the word of a gain of choices."""
    if isinstance(value, str) and WORD.fullmatch(value):
        return value
    if isinstance(value, (bool, str)) or value is None:
        raise InvalidParameterError(name, value, "a number, numbers per joint, or a matrix")
    array = np.asarray(value, dtype=float)
    if array.ndim >= 2 and array.shape[0] == 1 and array.ndim in (2, 3):  # one row or matrix for every run
        array = array[0]
    if array.ndim > 2 or array.size == 0 or (array.ndim == 2 and array.shape[0] != array.shape[1]):
        raise InvalidParameterError(
            name, f"array of shape {array.shape}", "one value set: a number, a row, or a square matrix"
        )
    if not np.all(np.isfinite(array)):
        raise InvalidParameterError(name, array.tolist(), "finite numbers")
    return ",".join(_number(x) for x in array.ravel())


def _checked_text(what: str, text: str) -> str:
    if not isinstance(text, str) or not text or SETTING.search(text):
        raise InvalidParameterError(
            what, text, "text without '@NAME=' (it would start a setting of the variant)"
        )
    return text


def format_variant(
    law: str,
    gains: Mapping[str, Any] | None = None,
    *,
    defaults: Mapping[str, Any] | None = None,
    model: str | None = None,
    p0: str | None = None,
) -> str:
    """A run's settings as a variant: ``format_variant("pd", {"kp": (200, 150)})`` is
    ``"pd@kp=200,150"``, which :func:`parse_variant` reads back to the same numbers.

    Args:
        law: The law as a command takes it (a registered name, ``file.py:Class``, ``module:Class``).
        gains: Gains by name, written in this order (a law's ``gains.values()`` is its
            declaration order): a number, numbers per joint, or a matrix (one value set;
            written row by row); each number as the shortest text that reads back to it.
            None (left to the robot) is left out.
        defaults: The law's gains in a default run; a gain equal to its default (the same
            numbers, a scalar equal to a constant row) is left out.
        model: The parameter file the law's model believes (``@model=``).
        p0: The parameter file the estimates start at (``@p0=``).

    Raises:
        InvalidParameterError: a value that is no single value set (per-run rows, NaN), both
            ``model`` and ``p0``, or text holding ``@NAME=`` (it would read back as a setting).
    """
    if model is not None and p0 is not None:
        raise InvalidParameterError("model, p0", (model, p0), "one parameter file per run: model or p0")
    parts = [_checked_text("law", law)]
    for name, value in (gains or {}).items():
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or name in PARAMETER_KEYS:
            raise InvalidParameterError("gain", name, "a gain's field name (not model or p0)")
        if value is None:  # left to the robot: its default
            continue
        if defaults is not None and defaults.get(name) is not None and _same_value(value, defaults[name]):
            continue
        parts.append(f"{name}={_value_text(name, value)}")
    for key, path in (("model", model), ("p0", p0)):
        if path is not None:
            parts.append(f"{key}={_checked_text(key, path)}")
    return "@".join(parts)


def _same_value(a: Any, b: Any) -> bool:
    """Whether two gain values are the same: the same word, or :func:`_same_numbers`."""
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    return _same_numbers(a, b)


def _same_numbers(a: Any, b: Any) -> bool:
    """Whether two gain values hold the same numbers once broadcast (``50`` and ``(50, 50)``;
    beside a matrix, ``s`` is ``s I`` and k numbers its diagonal, as a matrix gain reads them)."""
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    x, y = (v[0] if v.ndim in (2, 3) and v.shape[0] == 1 else v for v in (x, y))
    x, y = _as_matrix(x, y), _as_matrix(y, x)
    try:
        x, y = np.broadcast_arrays(x, y)
    except ValueError:
        return False
    return bool(np.array_equal(x, y))


def _as_matrix(value: np.ndarray, beside: np.ndarray) -> np.ndarray:
    """``value`` as a matrix when ``beside`` is a square matrix (k, k) and it is a number or k numbers."""
    if beside.ndim == 2 and beside.shape[0] == beside.shape[1] and value.ndim < 2:
        k = beside.shape[0]
        if value.ndim == 0:
            return value * np.eye(k)
        if value.shape == (k,):
            return np.diag(value)
    return value


def file_stem(key: str) -> str:
    """A row's name as a file-name prefix: itself when it is letters, digits, ``._-`` (every
    registered name), else those characters with a short hash of the whole name, so that two
    rows never share their figures (``pd@kp=200,150`` → ``pd-kp-200-150-3f0c2a1b``)."""
    if re.fullmatch(r"[A-Za-z0-9._-]+", key):
        return key
    slug = re.sub(r"[^A-Za-z0-9.]+", "-", key).strip("-.")[:48]
    return f"{slug}-{hashlib.sha1(key.encode()).hexdigest()[:8]}"


__all__ = [
    "PARAMETER_KEYS",
    "SETTING",
    "Variant",
    "file_stem",
    "format_variant",
    "gain_value",
    "parse_variant",
    "parse_variants",
    "split_variant",
]
