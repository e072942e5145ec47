"""Studies over many runs.

==================  ===================================================================
``batch.py``        :func:`simulate_batch`: N runs together, each run's metrics streamed
``sweep.py``        Monte Carlo sweeps (``twolink-pin sweep``): drawn cases, chunks, rows
                    streamed to Parquet / CSV / JSON, summary from the dataset
``cluster.py``      Dask for sweeps: a LocalCluster on 127.0.0.1 or a scheduler, tasks as
                    completed, cancelled on exit (optional: ``twolink-pin[cluster]``)
``comparison.py``   every law side by side: our Table 2
==================  ===================================================================
"""
