"""Many models across processes (`validate --jobs N`): the same results, in the order the
models were given, so the report does not depend on which worker finished first.

`prepare()` runs in this process first (validate imports its rule modules and readers),
and the workers are forked after it (where the platform allows fork), so each starts with
those modules instead of importing them again; every item, the first too, is then done by
the workers. A worker takes a run of neighbouring items at a time (models of one
directory share meshes, which a worker reads once).

Small inputs stay serial: a worker is only started for every MIN_ITEMS_PER_WORKER items
(two workers for four models, none for three), since forking and collecting results
cost more than a model or two take. And no more workers are started than the machine
has idle processors, by its one-minute load average (as `make -l` holds back jobs): on a
busy 2-core machine two workers only take turns on one core, and pay for the fork and
for reading each shared mesh twice (measured: docs/validate.md).
"""

from __future__ import annotations

import os
from typing import Callable, Sequence, TypeVar

from reedtool.errors import ReedtoolError

T = TypeVar("T")
R = TypeVar("R")


def available_cpus() -> int:
    """The processors this process may run on (its affinity, not the machine's count)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:          # not Linux
        return os.cpu_count() or 1


MIN_ITEMS_PER_WORKER = 2

# The function a forked worker runs: set before the pool forks, so it (and what it holds,
# e.g. robots already loaded) is inherited rather than pickled for every item.
_forked_func: Callable | None = None


def _call(func, item):
    try:
        return True, func(item)
    except ReedtoolError as exc:
        # Raised again in the parent as itself: an exception pickles only its message.
        return False, (exc.message, exc.file, exc.line, exc.hint)


def _call_forked(item):
    return _call(_forked_func, item)


def _call_pickled(job):
    return _call(*job)


def idle_cpus(load: float | None = None) -> int:
    """The available processors the rest of the machine leaves idle, this process's own
    share counted as idle (a one-minute load average of 1.0 on 2 CPUs is this run)."""
    cpus = available_cpus()
    if load is None:
        try:
            load = os.getloadavg()[0]
        except (AttributeError, OSError):      # not available: assume an idle machine
            return cpus
    return max(1, min(cpus, int(cpus - max(load - 1.0, 0.0) + 0.5)))


def workers_for(jobs: int, n_items: int, load: float | None = None) -> int:
    """How many processes `jobs` (0: one per available CPU) gives `n_items` items: at most
    one per MIN_ITEMS_PER_WORKER items and one per idle CPU (`load`: the one-minute load
    average, read when None); 1 means serial, in this process."""
    jobs = available_cpus() if jobs == 0 else jobs
    wanted = min(jobs, n_items // MIN_ITEMS_PER_WORKER)
    if wanted <= 1:
        return 1
    return max(1, min(wanted, idle_cpus(load)))


def map_models(func: Callable[[T], R], items: Sequence[T], jobs: int = 1,
               prepare: Callable[[], object] | None = None) -> list[R]:
    """[func(item) for item in items], in `jobs` processes (0: one per available CPU;
    fewer for few items, see `workers_for`).

    The items and results must pickle (and `func` too where processes cannot fork). A
    ReedtoolError raised for an item is raised here, the first in item order.
    """
    workers = workers_for(jobs, len(items))
    if workers <= 1:
        return [func(item) for item in items]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    global _forked_func

    if prepare is not None:
        prepare()             # imports the forked workers then start with
    fork = "fork" in multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if fork else None)
    # Neighbouring items in one task: fewer round trips, and a worker reads the meshes a
    # directory's models share once. Four tasks per worker keep the load balanced.
    chunk = max(1, len(items) // (workers * 4))
    _forked_func = func
    try:
        with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            outcomes = list(pool.map(_call_forked, items, chunksize=chunk) if fork
                            else pool.map(_call_pickled, [(func, item) for item in items],
                                          chunksize=chunk))
    finally:
        _forked_func = None
    results = []
    for ok, value in outcomes:
        if not ok:
            raise ReedtoolError(*value)
        results.append(value)
    return results
