"""Studies over many runs.

======================  ====================================================================================
``batch.py``            :func:`simulate_batch`: N runs together, each run's metrics streamed
``sweep.py``            Monte Carlo sweeps (``twolink-pin sweep``): :func:`run_sweep`, which
                        streams the rows to Parquet / CSV / JSON and summarises the dataset
``sweep_cases.py``      the study (``SweepConfig``: a ``RunSpec`` plus the draws), the cases
``sweep_rows.py``       the columns, a chunk's runs as rows, the summary statistics
``sweep_writers.py``    Parquet parts, runs.csv / runs.json, metadata, distributions.png
``sweep_transport.py``  what a Dask worker gets (robot, law file) and the chunk task
``cluster.py``          Dask for sweeps: a LocalCluster on 127.0.0.1 or a scheduler, tasks as
                        completed (each bounded by ``--timeout``), cancelled on exit (optional:
                        ``twolink-pin[cluster]``)
``cluster_startup.py``  reaching a scheduler (fail fast), distributed's log kept while a LocalCluster starts
``cluster_errors.py``   a cluster that cannot run the work; a task past its bound
``comparison.py``       every law side by side: our Table 2
======================  ====================================================================================
"""
