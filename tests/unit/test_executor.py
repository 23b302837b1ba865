"""The one executor layer (bayesfo.parallel.executor): which executor a number of processes
gives, and the in-process executor behaving as a pool does."""

from __future__ import annotations

import pytest

from bayesfo.errors import InputError
from bayesfo.parallel import InlineExecutor, LazyPool, executor, runs_here


def test_the_processes_asked_for_choose_the_executor():
    with executor(1, 5) as pool:
        assert isinstance(pool, InlineExecutor) and runs_here(pool)
    with executor(4, 1) as pool:  # one task: no process to start
        assert isinstance(pool, InlineExecutor)
    with executor(0, 3) as pool:  # automatic: started only by a task
        assert isinstance(pool, LazyPool) and not pool.started and runs_here(pool)
    for bad in (-1, 1.5, True):
        with pytest.raises(InputError, match="workers must be a non-negative integer"):
            with executor(bad, 2):
                pass


def test_the_inline_executor_runs_at_submit_and_keeps_errors_in_the_future():
    ran = []
    pool = InlineExecutor()
    future = pool.submit(lambda x: ran.append(x) or 2 * x, 21)
    assert ran == [21] and future.done() and future.result() == 42
    failed = pool.submit(lambda: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        failed.result()
    seen = []
    failed.add_done_callback(seen.append)  # a finished future calls back at once
    assert seen == [failed]

    def interrupted():
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):  # not kept for later: Ctrl-C ends the run now
        pool.submit(interrupted)


def _settle_twice():
    """In a worker: settle_worker called twice; the loads it ran and the objects frozen after
    the first call."""
    import gc

    from bayesfo.parallel import settle_worker

    loads = []
    settle_worker(lambda: loads.append("first"))
    frozen = gc.get_freeze_count()
    settle_worker(lambda: loads.append("second"))
    return loads, frozen


def test_a_pool_worker_settles_once_and_this_process_never():
    """settle_worker loads and freezes in a worker process of new_pool, once; in any other
    process (this one, as a batch run in-process) it leaves the collector alone."""
    import gc

    from bayesfo.parallel import new_pool, settle_worker, worker_environment

    loads = []
    before = gc.get_freeze_count()
    settle_worker(lambda: loads.append("here"))
    assert loads == [] and gc.get_freeze_count() == before
    with worker_environment():
        pool = new_pool(1)  # spawned: a worker starts with nothing frozen
        try:
            loads, frozen = pool.submit(_settle_twice).result(timeout=120)
        finally:
            pool.shutdown(wait=True)
    assert loads == ["first"]
    assert frozen > 1_000  # numpy and the package's modules at least
