"""``twolink-pin report``: the whole pipeline as one offline HTML page.

==================  ===================================================================
``build.py``        :func:`build_report`: the runs (worker processes), facts, errata
``facts.py``        the model, the torque check, the twolink's closed-form check, Table 1
``pages.py``        ``index.html`` (from ``templates/report.html``), ``report.md``, JSON
``templates/``      the page's Jinja2 template (package data)
==================  ===================================================================
"""

from twolink_pin.report.build import MARKER, MAX_WORKERS, ReportOptions, build_report

__all__ = ["MARKER", "MAX_WORKERS", "ReportOptions", "build_report"]
