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


def _call(job):
    func, item = job
    try:
        return True, func(item)
    except ReedtoolError as exc:
        # Raised again in the parent as itself: an exception pickles only its message.
        return False, (exc.message, exc.file, exc.line, exc.hint)


def map_models(func: Callable[[T], R], items: Sequence[T], jobs: int = 1) -> list[R]:
    """[func(item) for item in items], in `jobs` processes (0: one per available CPU).

    `func` and the items must pickle (a module-level function, or a functools.partial of
    one). A ReedtoolError raised for an item is raised here, the first in item order.
    """
    jobs = available_cpus() if jobs == 0 else jobs
    if jobs <= 1 or len(items) < 2:
        return [func(item) for item in items]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    first = _call((func, items[0]))     # warms imports and caches for the forked workers
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else None)
    with ProcessPoolExecutor(max_workers=min(jobs, len(items) - 1), mp_context=context) as pool:
        outcomes = [first, *pool.map(_call, [(func, item) for item in items[1:]])]
    results = []
    for ok, value in outcomes:
        if not ok:
            raise ReedtoolError(*value)
        results.append(value)
    return results
