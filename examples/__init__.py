"""The examples the documentation's commands use, shipped with the package as
``twolink_pin.examples`` (``pyproject.toml`` maps this folder there): ``twolink-pin examples``
lists them and ``twolink-pin examples --copy DIR`` writes them into ``DIR``, so that the pages'
commands (``--trajectory examples/ur5_square_pose.toml``, ``examples/sliding_mode.py:SlidingMode``)
run from a ``pip install`` as from a clone. Nothing here is imported by the package.
"""

FILES = {
    "sliding_mode.py": "a sliding-mode law with a boundary layer, written as a user would (Writing a controller)",
    "jacobian_transpose.py": "a Jacobian-transpose task-space law in one file (Task space)",
    "twolink_light.urdf": "the twolink with every link 20 % light: a wrong model to believe (Control within limits)",
    "panda_fold_pose.toml": "the Panda's hand lowered near its base and raised, its elbow near its range (Control within limits)",
    "panda_square_pose.toml": "a 20-cm square with orientations for the Panda (Task space)",
    "ur5_square_pose.toml": "a 20-cm square with orientations for the UR5 (Task space)",
    "ur5_square.toml": "a 20-cm square of end-effector positions for the UR5 (Any robot)",
    "tutorial.ipynb": "the tutorial notebook: model, trajectory, two laws, figures, the arm in 3-D",
    "tutorial.py": "the same tutorial as a script (jupytext's percent format)",
}
"""Each shipped file with what it is (and the page that uses it)."""
