"""Studies over many runs.

==================  ===================================================================
``batch.py``        :func:`simulate_batch`: N runs together, each run's metrics streamed
``sweep.py``        Monte Carlo sweeps (``twolink-pin sweep``): drawn cases, rows, summary
``comparison.py``   every law side by side: our Table 2
==================  ===================================================================
"""
