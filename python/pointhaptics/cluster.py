"""Where the simulations of a study or a fit run: Dask distributed (Debian's python3-distributed). By default a
local cluster on this machine (one worker process per core, one thread each: a simulation per core); with a
scheduler address, an existing Dask cluster, unchanged. Each simulation is one task; Dask sends it to a free
worker, and runs it again elsewhere if its worker dies."""
from __future__ import annotations

import contextlib
import logging
import os
import sys
import time


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None):
    """A dask.distributed Client: on the cluster at `scheduler` (tcp://HOST:PORT), or on a local cluster of
    `workers` processes (default: the machine's cores) with one thread each. Closed (and the local cluster
    stopped) on leaving."""
    from distributed import Client, LocalCluster

    if scheduler:
        if workers:
            raise ValueError("--workers is for the local cluster; an existing cluster (--scheduler) has its own workers")
        try:
            client = Client(scheduler, timeout="30s")
        except OSError as e:
            raise ValueError(f"--scheduler {scheduler}: no Dask scheduler answers there ({e})") from None
        try:
            _wait_for_workers(client, 1, f"the cluster at {scheduler}")
            yield client
        finally:
            client.close()
        return
    n = workers or os.cpu_count() or 1
    if n < 1:
        raise ValueError("workers: must be >= 1")
    # processes, one thread each: a simulation holds its worker's core, and the GIL is not shared; its web
    # server on a free port (two studies at once do not collide)
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        _wait_for_workers(client, n, "the local cluster")
        yield client


def _wait_for_workers(client, n: int, where: str, timeout: float = 120) -> None:
    try:
        client.wait_for_workers(n, timeout=timeout)
    except TimeoutError:
        raise ValueError(f"{where}: {n} worker{'s' if n > 1 else ''} did not start within {timeout:.0f} s "
                         f"({len(client.scheduler_info().get('workers', {}))} did)") from None


def add_arguments(parser) -> None:
    """The command-line options that say where the simulations run, and how chatty (study and fit alike)."""
    parser.add_argument("--scheduler", help="an existing Dask cluster, tcp://HOST:PORT (default: a local cluster)")
    parser.add_argument("--workers", type=int, help="local cluster: worker processes (default: the cores)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress")


def workers_of(client) -> int:
    return len(client.scheduler_info().get("workers", {}))


def run_all(client, function, calls: list[tuple], label: str = "runs", progress: bool = True) -> list:
    """Submits function(*args) for every args in `calls` and returns their results in order, printing progress
    (done, failed, elapsed, left) to stderr at most once a second. A result that is a dict with a non-empty
    "error" counts as failed. pure=False: a repeated call is run again, not taken from another's result."""
    from distributed import as_completed

    futures = [client.submit(function, *args, pure=False) for args in calls]
    index = {f.key: k for k, f in enumerate(futures)}
    results: list = [None] * len(futures)
    start = time.perf_counter()
    shown = 0.0
    done = failed = 0
    for future in as_completed(futures):
        results[index[future.key]] = future.result()
        done += 1
        r = results[index[future.key]]
        failed += bool(isinstance(r, dict) and r.get("error"))
        now = time.perf_counter() - start
        if progress and (now - shown >= 1.0 or done == len(futures)):
            shown = now
            left = now / done * (len(futures) - done)
            print(f"{label}: {done}/{len(futures)} done" + (f", {failed} failed" if failed else "") +
                  f", {now:.1f} s" + (f", about {left:.0f} s left" if done < len(futures) else ""), file=sys.stderr, flush=True)
    return results
