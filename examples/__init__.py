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
    "look_ahead.py": "computed torque that asks for the reference ahead to make up for a delay (Writing a controller)",
    "baxter_right_arm.toml": "Baxter's right arm as an arm of its own, the rest of its tree locked (Your arm, Any robot)",
    "wall.toml": "the contact lab's wall for the twolink: a plane at x = 0.55 m, 1000 N/m (Contact)",
    "wall_slide.toml": "press 10 N on the wall and slide along it, 6 s (Contact)",
    "table.toml": "a table under the Panda's hand, 5000 N/m (Contact)",
    "panda_table_slide.toml": "the Panda's hand presses 10 N on the table and slides 0.2 m (Contact)",
    "twolink_heavy.urdf": "the twolink with every link 20 % heavy: a wrong model to believe (scripts/benchmark.py --mpc-only)",
    "tutorial.ipynb": "the tutorial notebook: model, trajectory, two laws, figures, the arm in 3-D",
    "tutorial.py": "the same tutorial as a script (jupytext's percent format)",
}
"""Each shipped file with what it is (and the page that uses it)."""

ARMS = (
    "asr_twodof",
    "baxter_left",
    "baxter_right",
    "double_pendulum",
    "double_pendulum_continuous",
    "double_pendulum_simple",
    "finger_edu",
    "five_link_chain",
    "kinova",
    "panda",
    "pr2_left",
    "pr2_right",
    "so100",
    "so101",
    "talos_left_arm",
    "tiago_arm",
    "ur10",
    "ur10_joint_limited",
    "ur3",
    "ur3_joint_limited",
    "ur5",
    "ur5_joint_limited",
    "xarm7",
    "z1",
)
"""The published arms of ``arms/``, each a profile (``--robot examples/arms/NAME.toml``) that
``scripts/arms.py`` runs at every law's defaults (Your arm)."""
FILES.update(
    {
        f"arms/{name}.toml": "a published arm's profile, run at every law's defaults (Your arm)"
        for name in ARMS
    }
)
FILES["arms/five_link_chain.urdf"] = "five links about parallel axes, the arms' generated pendulum (Your arm)"
