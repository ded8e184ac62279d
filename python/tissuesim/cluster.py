"""The Dask cluster that calibration and sweeps run their simulations on: a
``distributed.LocalCluster`` of N single-threaded worker processes on this machine, or an
existing scheduler by address (``dask scheduler`` and ``dask worker ADDRESS`` on several
machines). The same code submits to either; Dask does all the scheduling, the retries of tasks
whose worker died, and the transfers.
"""

from __future__ import annotations

import argparse
import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager

from distributed import Client, LocalCluster


def add_cluster_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--workers N`` and ``--scheduler ADDRESS`` (mutually exclusive) to ``parser``."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="worker processes of a local Dask cluster (default: the number of CPUs)",
    )
    group.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="address of a running Dask scheduler (e.g. tcp://10.0.0.5:8786) instead of a "
        "local cluster; its workers need tissuesim installed",
    )


@contextmanager
def open_client(workers: int | None = None, scheduler: str | None = None) -> Iterator[Client]:
    """A Dask client: connected to ``scheduler`` if given, else to a new ``LocalCluster`` of
    ``workers`` processes (default: the CPU count), one thread each (each simulation is
    single-threaded; the processes run side by side). Closed on exit."""
    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 1:
        raise ValueError(f"--workers must be at least 1, got {n}")
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.CRITICAL,
    )
    with cluster, Client(cluster) as client:
        yield client


def worker_threads(client: Client) -> int:
    """Number of task slots (worker threads) the client's cluster has now."""
    workers = client.scheduler_info(n_workers=-1)["workers"]
    return sum(w.get("nthreads", 1) for w in workers.values())
