"""Figures: the desired trajectory, one run, and distributions over many runs.

The only part of the package that imports matplotlib. It never touches ``pyplot``: every
figure is a :class:`matplotlib.figure.Figure` drawn by its own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`, so no GUI backend is selected,
no global figure registry holds on to anything, and a figure is freed once saved. Every
file is written atomically (:func:`twolink_pin.files.atomic_write`). Figures know nothing
of a particular report: a caller that wants "cf. report Fig. N" in the titles passes
``figure_numbers`` (figure key → number), and the law's long name as ``title``.

===================  =====================================================================
``_style.py``        sizes, DPI, colours; the Agg figure, fixed margins per figure type,
                     figure titles
``_save.py``         rendering and saving: one draw on the Agg canvas (one mathtext parser),
                     the check that the labels fit the fixed margins, the atomic file
``_panels.py``       helpers on a panel: limit lines and their note, annotation placement,
                     legends moved off the curves, the max-|e| envelope, shaded spans,
                     plain log labels
``trajectory.py``    :func:`save_trajectory_figures`: each joint's desired motion, the arm
                     and end-effector path (in its plane, or a 3-D view and two projections),
                     the desired torque against the limits
``run.py``           :func:`save_simulation_figures`: one run's states, torques, and the
                     inertial / friction parameter errors (as the result declares them)
``parameters.py``    the parameter-error figures: a curve per parameter for a few (the
                     twolink), norms over time and a bar pair per parameter for many (the
                     base parameters of a 6- or 7-joint arm)
``state.py``         the figure of a law's own state (integrators, filters), per unit
``distribution.py``  :func:`save_distribution_figure`: histograms of metrics over a sweep
``cartesian.py``     :func:`save_end_effector_figure`: the end-effector path and its distance
                     to the desired one
``task.py``          :func:`save_task_error_figure`: a task-space law's position [mm] and
                     orientation [deg] errors over time
``contact.py``       :func:`~twolink_pin.plotting.contact.save_contact_figure`: runs against a
                     surface, the force with the desired force, the position along it, the
                     penetration
``overlay.py``       :func:`~twolink_pin.plotting.overlay.save_overlay_figure`: the runs of one
                     law's variants on the same axes (error envelope, torque)
``limits.py``        :func:`save_limits_figure`: several runs against one joint's range and
                     one joint's effort limit
``velocity_limits``  :func:`save_velocity_limits_figure`: several runs against one joint's
                     velocity and effort limits
``titles.py``        a figure's title as plain text, carried in its file (the report's captions)
===================  =====================================================================

Each module's private builder (``_trajectory_figures``, ``_simulation_figures``,
``_distribution_figure``) returns the :class:`Figure` objects keyed by file suffix, so
tests can check what is drawn. Units: time [s], angles [rad], rates [rad/s], positions
[m], torques [N·m].
"""

from twolink_pin.plotting.cartesian import save_end_effector_figure
from twolink_pin.plotting.distribution import save_distribution_figure
from twolink_pin.plotting.limits import save_limits_figure
from twolink_pin.plotting.run import save_simulation_figures
from twolink_pin.plotting.task import save_task_error_figure
from twolink_pin.plotting.trajectory import save_trajectory_figures
from twolink_pin.plotting.velocity_limits import save_velocity_limits_figure

__all__ = [
    "save_distribution_figure",
    "save_end_effector_figure",
    "save_limits_figure",
    "save_simulation_figures",
    "save_task_error_figure",
    "save_trajectory_figures",
    "save_velocity_limits_figure",
]
