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


_PARTIAL_RESULT = '''
import os, struct, time
from bayesfo import parallel

if __name__ == "__main__":
    with parallel.worker_environment():
        pool = parallel.new_pool(1, fork=True)
        pool.submit(time.sleep, 600)
        manager = pool._executor_manager_thread
        # The start of a result whose sender is ended before the rest (as SIGTERM may end a
        # worker): the manager thread reads it and waits for the rest.
        os.write(pool._result_queue._writer.fileno(), struct.pack("!i", 1_000_000) + b"x" * 10)
        time.sleep(1)
        parallel.terminate(pool)
        manager.join(timeout=60)
        print("manager ended" if not manager.is_alive() else "manager waits", flush=True)
'''


def test_terminate_frees_a_manager_waiting_for_the_rest_of_a_result(tmp_path):
    """A pool whose worker was ended while sending a result: terminate() leaves no thread
    waiting for the rest, so the process exits (the interpreter's exit joins that thread)."""
    import subprocess
    import sys

    script = tmp_path / "partial.py"
    script.write_text(_PARTIAL_RESULT)
    try:
        done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                              timeout=240)
    except subprocess.TimeoutExpired:
        pytest.fail("the process did not exit: its pool's manager thread still waits")
    assert done.returncode == 0, done.stderr
    assert done.stdout == "manager ended\n"
