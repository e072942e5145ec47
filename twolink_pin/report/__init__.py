"""``twolink-pin report``: the whole pipeline as one offline HTML page.

======================  ===============================================================
``build.py``            :func:`build_report`: the assembly (which laws, the pool, results)
``options.py``          :class:`ReportOptions`: a ``RunSpec`` and the report's own options
``runs.py``             one law's run and figures (a worker task), the trajectory's figures
``pool.py``             worker processes that never outlive the report (or in-process)
``facts.py``            the model, the torque check, the versions
``within_limits.py``    the section "The reference within the limits": three references, the laws on each
``pages.py``            ``index.html`` (from ``templates/report.html``), ``report.md``, JSON
``templates/``          the page's Jinja2 template (package data)
======================  ===============================================================

Nothing here names a robot or a law: what the report shows of a robot beyond the common
pipeline (its default laws, the animated one, figure numbers, its own sections) is declared
by its profile (:class:`twolink_pin.model.profile.ReportProfile`; the twolink's course-report
sections live in :mod:`twolink_pin.twolink.course_report`).
"""

from twolink_pin.report.build import MARKER, MAX_WORKERS, ReportOptions, build_report

__all__ = ["MARKER", "MAX_WORKERS", "ReportOptions", "build_report"]
