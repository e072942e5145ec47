"""Corpus laws (issue 30) that misbehave where user code runs besides ``compute``: while the
law is built (``__init__``, ``scaled_gains``), with processes, the working directory or NumPy's
global state, with torques that are not real numbers, with a state declaration that is wrong.
Each tracks with ``τ = −kp e`` unless it says otherwise.
"""

from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from twolink_pin import Controller, Gains, LawInput, LawOutput, Terms, gain
from twolink_pin.controllers.base import StateVariable


@dataclass(frozen=True, eq=False)
class HostileGains(Gains):
    """Gains of the laws below."""

    kp: Any = gain(100.0, unit="N·m/rad", doc="stiffness")


@dataclass(frozen=True, eq=False)
class DerivedGains(Gains):
    """A gain derived from the robot (``scaled_gains``)."""

    kp: Any = gain(None, per="joint", unit="N·m/rad", doc="stiffness, derived from the robot")


class _Base(Controller):
    title = "misbehaves"
    Gains = HostileGains

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput(-self.gains.kp * (x.q - x.q_des))


class InitRaises(_Base):
    """``__init__`` raises (line 51 of this file)."""

    name = "corpus-hostile-init-raises"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        raise RuntimeError("corpus: the law's constructor failed")


class InitSleeps(_Base):
    """``__init__`` never returns."""

    name = "corpus-hostile-init-sleeps"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        time.sleep(3600)


class InitExits(_Base):
    """``__init__`` calls ``sys.exit(0)``."""

    name = "corpus-hostile-init-exits"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        sys.exit(0)


class ScaledGainsSpins(_Base):
    """``scaled_gains`` never returns (a busy loop)."""

    name = "corpus-hostile-scaled-gains-spins"
    Gains = DerivedGains

    def scaled_gains(self) -> dict[str, Any]:
        while True:
            pass


class ScaledGainsRaises(_Base):
    """``scaled_gains`` raises KeyError (line 92 of this file)."""

    name = "corpus-hostile-scaled-gains-raises"
    Gains = DerivedGains

    def scaled_gains(self) -> dict[str, Any]:
        return {"kp": {}["missing"]}


class ComplexTorque(_Base):
    """Returns a complex torque (a zero imaginary part: still not a real number)."""

    name = "corpus-hostile-complex-torque"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput((-self.gains.kp * (x.q - x.q_des)).astype(complex))


class StringTorque(_Base):
    """Returns torques as strings."""

    name = "corpus-hostile-string-torque"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput((-self.gains.kp * (x.q - x.q_des)).astype(str))


class ObjectTorque(_Base):
    """Returns an object array of Python floats."""

    name = "corpus-hostile-object-torque"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput((-self.gains.kp * (x.q - x.q_des)).astype(object))


class Chdir(_Base):
    """Moves the working directory to ``elsewhere`` (a folder beside it) at its first step."""

    name = "corpus-hostile-chdir"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if os.path.isdir("elsewhere"):
            os.chdir("elsewhere")
        return super().compute(x, terms)


class NumpyState(_Base):
    """Changes NumPy's global state: errors raise, arrays print with one digit, the global
    random generator is seeded."""

    name = "corpus-hostile-numpy-state"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        np.seterr(all="raise")
        np.set_printoptions(precision=1)
        np.random.seed(0)  # noqa: NPY002  # the legacy global generator is the point
        return super().compute(x, terms)


class StartsProcess(_Base):
    """Starts ``sleep 600`` at its first step and returns."""

    name = "corpus-hostile-starts-process"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if not hasattr(self, "child"):
            self.child = subprocess.Popen(["sleep", "600"])
        return super().compute(x, terms)


class StartsMultiprocessing(_Base):
    """Starts a (non-daemon) ``multiprocessing`` child that sleeps 600 s: Python's exit would
    wait for it."""

    name = "corpus-hostile-starts-multiprocessing"

    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        if not hasattr(self, "child"):
            self.child = multiprocessing.get_context("fork").Process(target=time.sleep, args=(600,))
            self.child.start()
        return super().compute(x, terms)


class _Stateful(_Base):
    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        return LawOutput(-self.gains.kp * (x.q - x.q_des), np.zeros_like(x.z))


class StateNamedTwice(_Stateful):
    """Declares two state entries named ``s``."""

    name = "corpus-hostile-state-named-twice"

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (
            *super().state_variables(),
            StateVariable("s", "1", "filter"),
            StateVariable("s", "1", "filter"),
        )


class StateNameEmpty(_Stateful):
    """Declares a state entry with an empty name."""

    name = "corpus-hostile-state-name-empty"

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (*super().state_variables(), StateVariable("", "1", "filter"))


class StateWrongSize(_Stateful):
    """Declares two state entries and gives an initial state of three."""

    name = "corpus-hostile-state-wrong-size"

    def state_variables(self) -> tuple[StateVariable, ...]:
        return (
            *super().state_variables(),
            StateVariable("a", "1", "filter"),
            StateVariable("b", "1", "filter"),
        )

    def initial_state(self) -> np.ndarray:
        return np.zeros(3)
