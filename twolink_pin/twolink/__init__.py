"""Everything specific to the course report's 2-link planar arm, in one place.

============================  ==============================================================
``lumped_map.py``             the report's parameters (p1, p2, p3) as a parameter map
``closed_form.py``            the report's closed-form model: an independent cross-check
``course_equations.py``       the report's formulas in SymPy, and p1, p2, p3 found from the
                              equations derived from the URDF (:mod:`twolink_pin.symbolic`)
``errata.py``                 where the report is wrong or silent, with the evidence
``excitation.py``             its stored excitations (identification, adaptation) and why the
                              report's adaptive estimates are still far from p at 30 s
``course_report.py``          the report's sections its profile declares (closed-form check,
                              Table 1, Table 2, errata, the identification section)
``report_identification.py``  the identification section's worker tasks and assembly
============================  ==============================================================

Nothing outside this package depends on the twolink; the package imports only the generic
modules it builds on. (This docstring imports nothing, so any of its modules can be
imported alone.)
"""
