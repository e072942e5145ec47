"""Finding a control law from what a user typed: a name, ``file.py:Class`` or ``module:Class``.

* a registered name (``pd``, ``adaptive``, …, or one a plug-in registered);
* ``path/to/file.py:ClassName`` — the file is imported as a module of its own (its
  directory is not put on ``sys.path``) and the class is taken from it;
* ``package.module:ClassName`` — imported with :func:`importlib.import_module`;
* installed packages add laws through the entry-point group
  :data:`ENTRY_POINT_GROUP` (``name = "package.module:ClassName"``), loaded on first use.

Every failure is a :class:`~twolink_pin.errors.ControllerSpecError` naming the reference
and what is wrong (missing file, no such class, not a controller, the file raised).
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.metadata
import importlib.util
import inspect
import sys
from pathlib import Path

from twolink_pin.controllers.base import CONTROLLERS, Controller
from twolink_pin.controllers.gains import check_count, check_width, spec_of
from twolink_pin.errors import ControllerSpecError, InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.user_code import guarded

ENTRY_POINT_GROUP = "twolink_pin.controllers"
"""Entry-point group through which installed packages add control laws."""

_entry_points_loaded = False
_broken_plugins: dict[str, str] = {}
"""Plug-in name → why it could not be loaded (kept so that asking for it by name says why)."""


def _raised(exc: BaseException) -> str:
    """What user code raised, in words (``sys.exit`` spelled as such)."""
    if isinstance(exc, SystemExit):
        return f"called sys.exit({exc.code!r})"
    return f"raised {type(exc).__name__}: {exc}"


def load_entry_points() -> list[str]:
    """Import every law registered through :data:`ENTRY_POINT_GROUP` (once); returns the
    problems met, one line each (a broken plug-in must not break the built-in laws; it is
    listed by :func:`broken_plugins` and named when asked for)."""
    global _entry_points_loaded
    if _entry_points_loaded:
        return list(_broken_plugins.values())
    _entry_points_loaded = True
    for entry in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        try:
            cls = entry.load()
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # a plug-in's own failure (even sys.exit): reported, not fatal
            _broken_plugins[entry.name] = (
                f"plug-in {entry.name!r} ({entry.value}): importing it {_raised(exc)}"
            )
            continue
        if not (inspect.isclass(cls) and issubclass(cls, Controller)):
            _broken_plugins[entry.name] = f"plug-in {entry.name!r} ({entry.value}): not a Controller subclass"
    return list(_broken_plugins.values())


def broken_plugins() -> dict[str, str]:
    """Plug-ins registered under :data:`ENTRY_POINT_GROUP` that could not be loaded: name →
    the reason (one line)."""
    load_entry_points()
    return dict(_broken_plugins)


def available_controllers() -> dict[str, type[Controller]]:
    """Every law that can be named: the built-in ones and the installed plug-ins."""
    import twolink_pin.controllers  # noqa: F401  # the built-in laws register on import

    load_entry_points()
    return dict(CONTROLLERS)


def _file_module_name(path: Path) -> str:
    """The module name a law file is imported under (one per resolved path)."""
    resolved = path.expanduser().resolve()
    digest = hashlib.sha1(str(resolved).encode()).hexdigest()[:10]
    return f"twolink_pin_user_{resolved.stem}_{digest}"


def _from_file(spec: str, file_part: str, class_name: str) -> type:
    path = Path(file_part).expanduser()
    if not path.is_file():
        reason = "no such file" if not path.exists() else "not a regular file"
        raise ControllerSpecError(spec, f"{reason}: {path}")
    if path.suffix != ".py":
        raise ControllerSpecError(spec, f"expected a Python file ending in .py, got {path.name}")
    module_name = _file_module_name(path)
    resolved = path.resolve()
    module = sys.modules.get(module_name)
    if module is None:
        loader_spec = importlib.util.spec_from_file_location(module_name, resolved)
        if loader_spec is None or loader_spec.loader is None:  # pragma: no cover  # .py always has a loader
            raise ControllerSpecError(spec, f"cannot import {path}")
        module = importlib.util.module_from_spec(loader_spec)
        sys.modules[module_name] = module
        try:
            with guarded(spec, f"importing {path}"):
                loader_spec.loader.exec_module(module)
        except BaseException:
            sys.modules.pop(module_name, None)
            raise
    if not hasattr(module, class_name):
        found = sorted(
            n
            for n, v in vars(module).items()
            if inspect.isclass(v) and issubclass(v, Controller) and not inspect.isabstract(v)
        )
        raise ControllerSpecError(
            spec, f"{path} has no class {class_name!r} (controllers in it: {found or 'none'})"
        )
    return getattr(module, class_name)


def _from_module(spec: str, module_name: str, class_name: str) -> type:
    if importlib.util.find_spec(module_name.partition(".")[0]) is None:
        raise ControllerSpecError(spec, f"cannot import module {module_name!r} (no module of that name)")
    with guarded(spec, f"importing {module_name!r}"):  # its own failure, sys.exit and MemoryError included
        module = importlib.import_module(module_name)
    if not hasattr(module, class_name):
        raise ControllerSpecError(spec, f"module {module_name!r} has no class {class_name!r}")
    return getattr(module, class_name)


def load_controller(spec: str) -> type[Controller]:
    """The control-law class ``spec`` refers to (see the module docstring).

    Raises:
        ControllerSpecError: no such law, file, module or class, or not a controller.
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ControllerSpecError(str(spec), "expected a law name, path/to/file.py:Class or module:Class")
    known = available_controllers()
    if spec in known:
        return known[spec]
    if spec in _broken_plugins:
        raise ControllerSpecError(spec, _broken_plugins[spec])
    location, sep, class_name = spec.rpartition(":")
    if not sep or not location or not class_name.isidentifier():
        raise ControllerSpecError(
            spec,
            f"no law of that name; registered laws are {', '.join(known)}; or give path/to/file.py:Class "
            "or package.module:Class",
        )
    is_file = location.endswith(".py") or "/" in location or "\\" in location
    cls = _from_file(spec, location, class_name) if is_file else _from_module(spec, location, class_name)
    if not (inspect.isclass(cls) and issubclass(cls, Controller)):
        raise ControllerSpecError(spec, f"{class_name} is not a twolink_pin Controller subclass")
    if inspect.isabstract(cls):
        raise ControllerSpecError(
            spec, f"{class_name} is abstract: it must implement compute(self, x, terms)"
        )
    if "name" not in cls.__dict__:
        raise ControllerSpecError(spec, f"{class_name} must declare its own name = '...'")
    return cls


def reload_controller(spec: str) -> type[Controller]:
    """The law of ``spec`` read again from its file (``tune --watch``: the file was saved);
    a registered name or a module: as :func:`load_controller`.

    Raises:
        ControllerSpecError: as :func:`load_controller` (the file raised: its message).
    """
    location, sep, _ = spec.rpartition(":") if isinstance(spec, str) else ("", "", "")
    if sep and (location.endswith(".py") or "/" in location or "\\" in location):
        sys.modules.pop(_file_module_name(Path(location)), None)
    return load_controller(spec)


def check_profile_gains(robot: RobotModel) -> None:
    """Refuse a robot profile file's ``[gains.LAW]`` table of a law that is not registered, or
    with a gain the law does not have or a value it refuses, naming ``FILE: gains.LAW[.NAME]``
    (a profile written in code is the catalog's own: not checked here).

    Raises:
        InvalidParameterError: the first such table or gain.
    """
    file = robot.profile.file
    if file is None:
        return
    laws = available_controllers()
    for law, table in robot.gain_presets.items():
        cls = laws.get(law)
        if cls is None:
            raise InvalidParameterError(
                f"{file}: gains.{law}", dict(table), f"a table of a registered law: {', '.join(laws)}"
            )
        names = cls.Gains.field_names()
        unknown = [name for name in table if name not in names]
        if unknown:
            raise InvalidParameterError(
                f"{file}: gains.{law}.{unknown[0]}", table[unknown[0]], f"a gain of {law}: {', '.join(names)}"
            )
        widths = cls.gain_widths(robot)
        try:
            for name, value in table.items():  # the count of numbers before their values
                spec = spec_of(cls.Gains, name)
                if spec.per != "scalar":
                    check_count(name, value, spec, *widths[spec.per])
            gains = cls.Gains(**table)
            for name in table:  # a matrix of the wrong size for this arm
                spec = spec_of(cls.Gains, name)
                if spec.per != "scalar":
                    check_width(name, getattr(gains, name), *widths[spec.per])
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"{file}: gains.{law}.{exc.name}", exc.value, exc.expected) from None
