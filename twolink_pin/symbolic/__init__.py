"""The equations of motion in closed form, derived with SymPy from an arm's kinematic tree.

=====================  ==================================================================
``equations.py``       :func:`derive_equations` → :class:`Equations`: M, C, g and the
                       regressor in the base parameters, with the arm's numbers
``support.py``         which arms it derives (revolute and prismatic joints, open chains, at
                       most ``MAX_JOINTS``) and the one line that says why not
``skeleton.py``        the tree read from a Pinocchio model as exact data (the cache's key)
``trig_ring.py``       polynomials in cos and sin of the angles: the exact, canonical algebra
``kinematics.py``      each body's pose and its Jacobian in its own frame
``lagrange.py``        M and g term by term in the inertial parameters; C by the Christoffel
                       symbols; the check that Ṁ − 2C is skew-symmetric
``grouping.py``        the base parameters as exact combinations (Gautier's choice, exactly)
``derivation.py``      the steps above in order; the derivation as JSON
``cache.py``           derivations kept on disk, one per kinematic content
``readable.py``        polynomials as sums of cos and sin of joint angles, by parameter
``formats.py``         the equations as terminal text, a LaTeX document, JSON
``numpy_module.py``    the equations as a standalone numpy module (no twolink-pin)
=====================  ==================================================================

Needs only the model layer (and SymPy, imported when a derivation starts); used by the
``equations`` command, the report, and the twolink's check against the course's formulas
(:mod:`twolink_pin.twolink.course_equations`).
"""

from twolink_pin.symbolic.equations import Equations, derive_equations
from twolink_pin.symbolic.support import MAX_JOINTS, check_model, check_urdf, first_joints

__all__ = ["MAX_JOINTS", "Equations", "check_model", "check_urdf", "derive_equations", "first_joints"]
