"""The parameter sweep behind python/sweep.py, one module per job:

- grid: the grid of start values from the command line, the columns of a row
- runner: one FMU run of one point of the grid (what a Dask worker executes)
- cluster: the runs on a dask.distributed cluster
- driver: the sweep, serially or on a cluster, with E against a reference run
  and, from twins of the reference, over the window the scene is predictable in
- output: CSV and Parquet
- plot: the plots of a sweep
"""
