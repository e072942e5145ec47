"""The bad-input corpus of ``twolink-pin``: cases (``cases.py``) and how they run (``runner.py``)."""
