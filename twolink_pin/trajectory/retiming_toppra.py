"""toppra, imported for the retiming (:mod:`twolink_pin.trajectory.retiming`) without the
figures it never draws here.

``toppra.algorithm`` imports ``matplotlib.pyplot`` when it is imported (for its ``plot`` helper
of the controllable sets): in a fresh process that was 1.3 s of toppra's 5.9 s on a loaded
machine, paid by every ``trajectory --time-optimal``, ``optimize --cost time`` and the report's
limits section, which draw with the Agg backend later or never. :func:`import_toppra` imports
toppra with ``matplotlib.pyplot`` standing for a module that imports the real one the first
time toppra touches it (never, here), then takes the stand-in out of ``sys.modules``, so that
every other ``import matplotlib.pyplot`` gets the real module.
"""

from __future__ import annotations

import functools
import importlib
import logging
import sys
import types
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from twolink_pin.trajectory.retiming_path import PathPiece

PYPLOT = "matplotlib.pyplot"


class _LazyPyplot(types.ModuleType):
    """Stands for ``matplotlib.pyplot`` in a module that imported it: the real module is
    imported on the first attribute read."""

    def __getattr__(self, name: str) -> Any:
        if sys.modules.get(PYPLOT) is self:
            del sys.modules[PYPLOT]
        return getattr(importlib.import_module(PYPLOT), name)


def import_toppra() -> types.ModuleType:
    """``toppra`` with ``toppra.algorithm`` loaded, ``matplotlib.pyplot`` not imported by it
    (module docstring)."""
    stand_in = None
    if PYPLOT not in sys.modules:
        stand_in = sys.modules[PYPLOT] = _LazyPyplot(PYPLOT)
    try:
        import toppra
        import toppra.algorithm
    finally:
        if stand_in is not None and sys.modules.get(PYPLOT) is stand_in:
            del sys.modules[PYPLOT]
    return toppra


@functools.cache
def toppra_classes() -> Any:
    """toppra (imported here only, without pyplot: :func:`import_toppra`), its logger quiet,
    and the two classes on it: the path and the limits' rows."""
    toppra = import_toppra()
    from toppra.constraint import DiscretizationType, LinearConstraint
    from toppra.interpolator import AbstractGeometricPath

    logging.getLogger("toppra").setLevel(logging.ERROR)

    class Path(AbstractGeometricPath):
        def __init__(self, piece: PathPiece, nv: int) -> None:
            self.piece, self._nv = piece, nv

        def __call__(self, s: Any, order: int = 0) -> np.ndarray:
            out = self.piece.path(np.atleast_1d(np.asarray(s, dtype=float)), order)
            return out[0] if np.ndim(s) == 0 else out

        @property
        def dof(self) -> int:
            return self._nv

        @property
        def path_interval(self) -> np.ndarray:
            return np.array([self.piece.start, self.piece.end])

    class Limits(LinearConstraint):
        def __init__(self, params: Callable[[np.ndarray], tuple[np.ndarray, ...]], nv: int) -> None:
            super().__init__()
            self.params, self.dof, self.identical = params, nv, True
            self.set_discretization_type(DiscretizationType.Collocation)  # the rows: :func:`_params`

        def compute_constraint_params(self, path: Any, gridpoints: np.ndarray) -> Any:
            a, b, c, F, g, xbound = self.params(gridpoints)
            return a, b, c, F, g, None, xbound

    return type("_TOPPRA", (), {"toppra": toppra, "Path": Path, "Limits": Limits})


__all__ = ["import_toppra", "toppra_classes"]
