"""``twolink-pin tune``: tune a law live in the browser, on a Viser page.

Every change of a control re-simulates the run in the background (latest wins: a change
supersedes the run waiting, and a run that ends after a newer change is dropped) and the
page shows the new run: the arm, its ghost and trail, the plots, the metrics beside the
previous run and the defaults, and the ``twolink-pin simulate …`` line that reproduces it —
period by period as the run goes (each column of the table cut to the same periods).

======================  ==============================================================
``latest.py``           :class:`LatestWins`: one worker, one waiting request, stuck runs left behind
``steps.py``            how a control's value steps (the log grid, whole knots) and how a number is shown
``knobs.py``            the controls of a law's gains, from its ``Gains`` declaration
``outcomes.py``         what a run is asked for and gives: request, finished run, part, period
``runner.py``           one run: simulated, measured, its gains and plant; each finished period at once
``periods.py``          a run's first k periods as a run (measured as the final table), other runs cut
``typed_js.py``         the page's script: typed values sent once on Enter or blur, focus holds playback
``typed.py``            the server's end of a typed number: each box's handler, numbers read and checked
``gain_controls.py``    the gains' sliders (on their grid) and ``NAME =`` boxes
``plant_controls.py``   the plant's controls and the ``PlantOptions`` they describe
``panel.py``            the controls' folders (gains, run, plant) and the ``RunSpec`` they describe
``results.py``          the results panel docked beside the controls: status, table, plots
``table.py``            the metrics table (HTML): this run beside the previous, defaults, kept
``scene.py``            the arm (Pinocchio's ``ViserVisualizer``), ghost, trail, playback
``plots.py``            joint errors, torques, task errors, the law's state; previous, defaults, kept
``command_folder.py``   the run as a ``simulate`` line, saved (``.npz``) and exported (``.html``)
``address.py``          ``--host`` and ``--port`` checked before the server starts
``outputs.py``          the page's file names kept inside the tuner's folder
``app.py``              :class:`Tuner`: the server, the runs shown as they come, keep, watch
======================  ==============================================================

The only part of twolink-pin that imports viser (in :mod:`.app`, :mod:`.scene`, lazily).
"""

from twolink_pin.tuning.app import Tuner
from twolink_pin.tuning.knobs import Knob, gains_from, knobs_of
from twolink_pin.tuning.latest import LatestWins

__all__ = ["Knob", "LatestWins", "Tuner", "gains_from", "knobs_of"]
