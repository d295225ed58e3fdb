"""Where independent units of work run: in this process, on a pool of local processes
(``--workers N``), or on a dask.distributed cluster (``--scheduler local`` starts one here,
``--scheduler tcp://HOST:PORT`` uses a running one).

:func:`map_units` calls one function on each unit's arguments and yields the results as
the units finish. Only the calling process (the client) gets the results, so what it
writes from them (progress records, result tables) has one writer, whatever the backend;
a unit writes only its own files. The results do not depend on the backend: callers that
need an order key the results themselves.

A cluster's workers must see the files at the same paths as the client (a shared file
system) and should run one task at a time (``dask worker ADDRESS --nthreads 1``): a unit
uses all the threads it is given.
"""

from __future__ import annotations

import logging
import os
import re
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from multiprocessing import get_context
from typing import Callable, Iterable, Iterator

LOCAL_CLUSTER = "local"
SCHEDULER_ADDRESS = re.compile(r"tcp://(?P<host>[^\s:/]+|\[[0-9A-Fa-f:.]+\]):(?P<port>[0-9]{1,5})")
CONNECT_TIMEOUT_S = 10.0
"""How long to try to reach a running scheduler before giving up (seconds)."""
DASK_MISSING = "--scheduler needs dask.distributed: pip install 'metricscenes[dask]'"


class BackendError(RuntimeError):
    """A scheduler that cannot be used (one-line message)."""


def check_scheduler(scheduler: str | None) -> None:
    """Refuse (:class:`BackendError`, one line) a ``--scheduler`` that cannot be used,
    before anything is written: not ``local`` nor ``tcp://HOST:PORT``, dask.distributed
    not installed, or no scheduler answering at that address."""
    if scheduler is None:
        return
    match = SCHEDULER_ADDRESS.fullmatch(scheduler)
    if scheduler != LOCAL_CLUSTER and not (match and 0 < int(match["port"]) < 65536):
        raise BackendError(f"--scheduler {scheduler!r}: expected 'local' or a dask scheduler address "
                           "tcp://HOST:PORT")
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise BackendError(DASK_MISSING) from None
    if is_remote(scheduler):
        with _dask_client(scheduler, workers=1):
            pass


def is_remote(scheduler: str | None) -> bool:
    """True where the units run on a running cluster (other machines, perhaps)."""
    return scheduler is not None and scheduler != LOCAL_CLUSTER


def runs_in_process(workers: int, scheduler: str | None) -> bool:
    """True where :func:`map_units` calls the function in this process, one unit after
    another (so it may be given callbacks and unpicklable objects)."""
    return scheduler is None and workers <= 1


def threads_per_unit(threads: int | None, workers: int, scheduler: str | None) -> int | None:
    """Threads each unit uses: ``threads`` if given; None on a running cluster (each
    worker's machine decides); else this machine's CPUs shared by the ``workers``."""
    if threads is not None or is_remote(scheduler):
        return threads
    return max(1, (os.cpu_count() or 1) // max(1, workers))


def map_units(function: Callable, units: Iterable[tuple], *, workers: int = 1,
              scheduler: str | None = None) -> Iterator:
    """Yield ``function(*args)`` for each ``args`` of ``units``, in the order they finish.

    ``scheduler`` None: in this process if ``workers`` <= 1, else on ``workers`` spawned
    processes that die with this one. ``local``: a dask LocalCluster of ``workers``
    processes of one thread each; ``tcp://HOST:PORT``: the cluster of that scheduler
    (``workers`` is then the cluster's business). ``function`` and the arguments must
    pickle unless the units run in this process. The first unit that fails raises its
    error here; closing the generator early (``contextlib.closing``) cancels the units
    not started.
    """
    units = list(units)
    if not units:
        return
    if runs_in_process(workers, scheduler):
        for args in units:
            yield function(*args)
    elif scheduler is None:
        yield from _on_process_pool(function, units, workers)
    else:
        yield from _on_dask(function, units, workers, scheduler)


def _on_process_pool(function: Callable, units: list[tuple], workers: int) -> Iterator:
    pool = ProcessPoolExecutor(min(workers, len(units)), mp_context=get_context("spawn"),
                               initializer=die_with_parent, initargs=(os.getpid(),))
    try:
        futures = [pool.submit(function, *args) for args in units]
        for future in as_completed(futures):
            yield future.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)  # on an error: no new unit starts


def _on_dask(function: Callable, units: list[tuple], workers: int, scheduler: str) -> Iterator:
    from distributed import as_completed as dask_as_completed

    with _dask_client(scheduler, workers) as client:
        futures = [client.submit(function, *args, pure=False) for args in units]
        try:
            for future in dask_as_completed(futures, loop=client.loop):
                yield future.result()
        finally:
            client.cancel(futures)


@contextmanager
def _dask_client(scheduler: str, workers: int):
    """A dask client on a new LocalCluster (``local``) or on the scheduler at ``scheduler``."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise BackendError(DASK_MISSING) from None
    if scheduler == LOCAL_CLUSTER:
        # dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536, which made a render unit
        # about 13 % slower here (docs/performance.md); its other settings (one BLAS thread) stay.
        environ = {name: value for name, value in dask.config.get("distributed.nanny.pre-spawn-environ").items()
                   if name != "MALLOC_TRIM_THRESHOLD_"}
        try:
            with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):  # read as the workers start
                # No dashboard (its port may be taken), warnings only from dask's own logs.
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
        except (RuntimeError, OSError) as exc:
            raise BackendError(f"--scheduler local: dask could not start {workers} workers ({_one_line(exc)})") from None
        with _timeout_as_backend_error(scheduler), cluster, Client(cluster, set_as_default=False) as client:
            yield client
        return
    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise BackendError(f"--scheduler {scheduler}: no dask scheduler answers there ({_one_line(exc)}); "
                           "start one (dask scheduler) or use --scheduler local") from None
    with _timeout_as_backend_error(scheduler), client:
        yield client


@contextmanager
def _timeout_as_backend_error(scheduler: str):
    """A dask timeout (a TimeoutError is an OSError: the CLI would call it "cannot write" the
    output) as one line that says what timed out and that finished units are kept."""
    try:
        yield
    except TimeoutError as exc:
        raise BackendError(f"--scheduler {scheduler}: dask timed out ({_one_line(exc)}); the units it finished "
                           "are kept: run the same command again to resume") from None


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def die_with_parent(parent_pid: int) -> None:
    """Worker initializer: on Linux, ask the kernel to SIGTERM this worker when its parent
    dies (a killed ``generate`` otherwise leaves its workers rendering, ~300 MB each),
    and leave at once if the parent died before this worker got here."""
    import ctypes
    import signal
    import sys

    if sys.platform.startswith("linux"):
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != parent_pid:
        os._exit(1)
