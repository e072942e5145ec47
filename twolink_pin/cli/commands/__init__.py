"""The commands of ``twolink-pin``: each a thin shell over the library, one module per family.

================  =====================================================================
``common.py``     what they share: the robot, the reference, the settings, one run
``model.py``      ``info``, ``robots``, ``controllers``, ``fk``, ``ik``, ``trajectory``
``identify.py``   ``identify``, ``excite``
``optimal.py``    ``optimize``, ``trajectory --time-optimal``
``run.py``        ``simulate``, ``compare``, ``report``
``animate.py``    ``animate``: a run, or a saved one, in 3-D
``sweep.py``      ``sweep``
``tune.py``       ``tune``
``equations.py``  ``equations``: the equations of motion in closed form
================  =====================================================================

Every command prints a readable summary, or JSON with ``--json``. The library is imported
inside each command, so ``--help`` stays fast.
"""

from __future__ import annotations

from twolink_pin.cli.commands.animate import cmd_animate
from twolink_pin.cli.commands.equations import cmd_equations
from twolink_pin.cli.commands.identify import cmd_excite, cmd_identify
from twolink_pin.cli.commands.model import (
    cmd_controllers,
    cmd_fk,
    cmd_ik,
    cmd_info,
    cmd_robots,
    cmd_trajectory,
)
from twolink_pin.cli.commands.optimal import cmd_optimize
from twolink_pin.cli.commands.run import cmd_compare, cmd_report, cmd_simulate
from twolink_pin.cli.commands.sweep import cmd_sweep
from twolink_pin.cli.commands.tune import cmd_tune

__all__ = [
    "cmd_animate",
    "cmd_compare",
    "cmd_controllers",
    "cmd_equations",
    "cmd_excite",
    "cmd_fk",
    "cmd_identify",
    "cmd_ik",
    "cmd_info",
    "cmd_optimize",
    "cmd_report",
    "cmd_robots",
    "cmd_simulate",
    "cmd_sweep",
    "cmd_trajectory",
    "cmd_tune",
]
