"""A function run in a fresh (spawned) process, for tests whose code forks: the test process
may hold threads that other tests left (a Dask client's), with which forking is not safe."""

from __future__ import annotations


def in_fresh_process(fn, *args):
    """``fn(*args)`` in a spawned process of its own; fails after 10 minutes."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from bayesfo import parallel

    # (a process of its own: a multiprocessing.Pool's are daemons, which may not fork; ended
    # without waiting, so that a hang fails the test instead of stalling the suite)
    fresh = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"))
    try:
        return fresh.submit(fn, *args).result(timeout=600)
    finally:
        parallel.terminate(fresh)
