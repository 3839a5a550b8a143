"""Many models across processes (`validate --jobs N`): the same results, in the order the
models were given, so the report does not depend on which worker finished first.

The first item is done in this process, and the workers are forked after it (where the
platform allows fork), so each starts with every module that item imported and every
file it cached (shared meshes) instead of loading them again.
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


def map_models(func: Callable[[T], R], items: Sequence[T], jobs: int = 1) -> list[R]:
    """[func(item) for item in items], in `jobs` processes (0: one per available CPU).

    The items and results must pickle (and `func` too where processes cannot fork). A
    ReedtoolError raised for an item is raised here, the first in item order.
    """
    jobs = available_cpus() if jobs == 0 else jobs
    if jobs <= 1 or len(items) < 2:
        return [func(item) for item in items]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    global _forked_func

    first = _call(func, items[0])     # warms imports and caches for the forked workers
    fork = "fork" in multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if fork else None)
    _forked_func = func
    try:
        with ProcessPoolExecutor(max_workers=min(jobs, len(items) - 1),
                                 mp_context=context) as pool:
            rest = (pool.map(_call_forked, items[1:]) if fork
                    else pool.map(_call_pickled, [(func, item) for item in items[1:]]))
            outcomes = [first, *rest]
    finally:
        _forked_func = None
    results = []
    for ok, value in outcomes:
        if not ok:
            raise ReedtoolError(*value)
        results.append(value)
    return results
