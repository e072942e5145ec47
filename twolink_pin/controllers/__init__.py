"""Tracking controllers: one law per file, registered by name when its class is defined.

=====================  ============================================================
``base.py``            :class:`Controller` (the contract), its state's declaration, the
                       registry :data:`CONTROLLERS`
``law_io.py``          what flows through ``compute``: ``LawInput``/``LawOutput``, the ``Terms``
                       protocol
``contact_input.py``   ``ContactInput``: the force sensor's wrench and the force reference
``gains.py``           :class:`Gains` and :func:`gain`: validated gains with units
``matrix_gains.py``    matrix gains (``K = κ M(q₀)``): read, checked, applied
``preview.py``         :class:`ReferencePreview`: the reference ahead of now a law asks for
``relaxation.py``      :class:`Relaxations`: the limits a law relaxed when they could not all hold
``loading.py``         :func:`load_controller`: a name, ``file.py:Class``, ``module:Class``
``pd.py``              ``pd`` — :class:`PDFeedforward` (report eq. 8)
``computed_torque.py`` ``computed-torque`` — :class:`ComputedTorque` (Slotine–Li)
``wrong_model.py``     ``robust`` — :class:`WrongModel` (Slotine–Li on β × the model)
``adaptive.py``        ``adaptive`` — :class:`Adaptive` (Slotine–Li adaptive)
``adaptive_friction``  ``adaptive-friction`` — :class:`AdaptiveFriction` (+ friction)
``pd_gravity.py``      ``pd-gravity`` — :class:`PDGravity` (PD + ĝ)
``pid.py``             ``pid`` — :class:`PID` (integral state, anti-windup)
``task_space.py``      what the task-space laws share (task rows, pose error, Λ, null space)
``osc.py``             ``osc`` — :class:`OperationalSpace` (Khatib)
``impedance.py``       ``impedance`` — :class:`Impedance` (Cartesian impedance + ĝ)
``qp_osc.py``          ``qp-osc`` — :class:`QPOperationalSpace` (``osc`` as a QP within the limits)
``mpc.py``             ``mpc`` — :class:`ModelPredictive` (a plan within the limits, replanned)
``force_loop.py``      what the force laws share: the sensor's normal force, its PI, anti-windup
``force.py``           ``force`` — :class:`ForceControl` (ĝ + Jᵀ(f_d + PI on the force error) − K_d q̇)
``hybrid.py``          ``hybrid`` — :class:`Hybrid` (Raibert–Craig: position along a surface, force across)
=====================  ============================================================
"""

# ruff: noqa: I001  # the laws register in import order: the report's order, kept by hand

from __future__ import annotations

from twolink_pin.controllers.base import CONTROLLERS, Controller, StateVariable
from twolink_pin.controllers.law_io import FrameTerms, LawInput, LawOutput, Terms
from twolink_pin.controllers.contact_input import ContactInput
from twolink_pin.controllers.gains import Gains, gain
from twolink_pin.controllers.preview import ReferencePreview
from twolink_pin.controllers.relaxation import Relaxations
from twolink_pin.controllers.pd import PDFeedforward, PDGains
from twolink_pin.controllers.computed_torque import DEFAULT_LAMBDA, ComputedTorque, SlotineLiGains
from twolink_pin.controllers.wrong_model import WrongModel, WrongModelGains
from twolink_pin.controllers.adaptive import Adaptive, AdaptiveGains
from twolink_pin.controllers.adaptive_friction import AdaptiveFriction, AdaptiveFrictionGains
from twolink_pin.controllers.pd_gravity import PDGravity, PDGravityGains
from twolink_pin.controllers.pid import PID, PIDGains
from twolink_pin.controllers.osc import OperationalSpace, OSCGains
from twolink_pin.controllers.impedance import Impedance, ImpedanceGains
from twolink_pin.controllers.qp_osc import QPOperationalSpace, QPOSCGains
from twolink_pin.controllers.mpc import MPCGains, ModelPredictive
from twolink_pin.controllers.force import ForceControl, ForceGains
from twolink_pin.controllers.hybrid import Hybrid, HybridGains
from twolink_pin.controllers.loading import available_controllers, load_controller

__all__ = [
    "CONTROLLERS",
    "DEFAULT_LAMBDA",
    "PID",
    "Adaptive",
    "AdaptiveFriction",
    "AdaptiveFrictionGains",
    "AdaptiveGains",
    "ComputedTorque",
    "ContactInput",
    "Controller",
    "ForceControl",
    "ForceGains",
    "FrameTerms",
    "Gains",
    "Hybrid",
    "HybridGains",
    "Impedance",
    "ImpedanceGains",
    "LawInput",
    "LawOutput",
    "MPCGains",
    "ModelPredictive",
    "OSCGains",
    "OperationalSpace",
    "PDFeedforward",
    "PDGains",
    "PDGravity",
    "PDGravityGains",
    "PIDGains",
    "QPOSCGains",
    "QPOperationalSpace",
    "ReferencePreview",
    "Relaxations",
    "SlotineLiGains",
    "StateVariable",
    "Terms",
    "WrongModel",
    "WrongModelGains",
    "available_controllers",
    "gain",
    "load_controller",
]
