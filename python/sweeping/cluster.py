"""The runs of a sweep on a dask.distributed cluster: the FMU scattered to
every worker, one task per point of the grid, the rows back in grid order."""

import math
import sys

from .grid import METRICS
from .runner import run_one


class ByValue:
    """A function that pickles by value, as cloudpickle.loads of its bytes,
    with what it uses from this package: the workers rebuild it with the
    cloudpickle that dask.distributed brings, without importing this package.
    (dask.distributed pickles a task's function by reference, by module and
    name, unless the function comes from __main__; this package is not.)"""

    def __init__(self, function):
        import cloudpickle

        cloudpickle.register_pickle_by_value(sys.modules[__package__])
        self.function = function
        self.pickled = cloudpickle.dumps(function)

    def __call__(self, *args, **kwargs):
        return self.function(*args, **kwargs)

    def __reduce__(self):
        import cloudpickle

        return cloudpickle.loads, (self.pickled,)


def run_on_cluster(client, data, digest, points, stop_time, step, progress, keep_positions=False):
    from distributed import progress as progress_bar
    from distributed import wait

    # The workers get run_one by value, so a cluster's workers need fmpy and
    # numpy but not these files.
    task = ByValue(run_one)
    # A key of its own (hash=False): a content-hashed key would be shared by
    # every sweep of the same FMU on this client, and this sweep's cancel at
    # the end could then drop the data a following sweep has just scattered.
    fmu_data = client.scatter(data, broadcast=True, hash=False)
    futures = [client.submit(task, fmu_data, digest, p, stop_time, step, keep_positions, pure=False) for p in points]
    if progress:
        progress_bar(futures)
        print()
    wait(futures)
    rows = []
    for point, future in zip(points, futures, strict=True):
        try:
            rows.append(future.result())
        except Exception as e:  # a worker that died on this run, ...
            row = dict(point)
            row.update({m: math.nan for m in METRICS})
            row.update(status="error", message=f"{type(e).__name__}: {e}", outputPoints=0, wallTime=math.nan, worker="")
            rows.append(row)
    client.cancel([fmu_data])
    return rows
