"""``twolink-pin report``: the whole pipeline as one offline HTML page.

======================  ===============================================================
``build.py``            :func:`build_report`: the assembly (which laws, the pool, results)
``options.py``          :class:`ReportOptions`: a ``RunSpec`` and the report's own options
``runs.py``             worker tasks: one law's run and figures, the trajectory's figures
``pool.py``             worker processes that never outlive the report (or in-process)
``identification.py``   the twolink's identification section (beside Fig. 27)
``facts.py``            the model, the torque check, the twolink's closed-form check, Table 1
``pages.py``            ``index.html`` (from ``templates/report.html``), ``report.md``, JSON
``templates/``          the page's Jinja2 template (package data)
======================  ===============================================================
"""

from twolink_pin.report.build import MARKER, MAX_WORKERS, ReportOptions, build_report

__all__ = ["MARKER", "MAX_WORKERS", "ReportOptions", "build_report"]
