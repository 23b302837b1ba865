"""Worker processes, and the one executor of a comparison's structures.

:func:`executor` gives a comparison its executor from the number of processes asked for: this process
(:class:`InlineExecutor`), a pool of worker processes (:func:`process_pool`), or the automatic
choice (:class:`LazyPool`, whose processes start only when a task needs them, so that a job of
quick tasks pays no start-up); every one has ``submit``, and the schedule that drives them is the
same. :func:`figure_processes` says from the CPU time left idle whether figures can be drawn
in a second process; :class:`SpareCPU` tells a worker that a CPU has been idle of late, and
:class:`Helper` runs part of its work (half of a tempered ladder's runs) in a process forked
from it. A batch runs its data sets on the same worker processes
(:func:`new_pool`) through its own schedule (:mod:`bayesfo.batch.executors`: one data set per
task, resumable, or a Dask cluster).

Workers are spawned, or forked where that is safe (a comparison's pools, see :func:`new_pool`
and :func:`fork_safe`), run one BLAS thread each,
ignore Ctrl-C (the parent answers it, once) and end when their parent dies, so an interrupted or
killed run never leaves orphans behind. :func:`process_pool` ends its workers at once when the
block that uses it raises.
"""

from __future__ import annotations

import ctypes
import gc
import os
import signal
import sys
import warnings
from concurrent.futures import Executor, Future
from contextlib import contextmanager

from .errors import InputError

#: Environment of worker processes: one BLAS thread each (the processes share the cores).
WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

_PR_SET_PDEATHSIG = 1  # prctl(2) option: a signal for this process when its parent dies


def available_cpus() -> int:
    """CPUs this process may run on (its affinity where the system tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1



def check_workers(workers, name: str = "workers") -> int:
    """``workers`` (a number of processes, 0: one per CPU) after checking it; the message
    calls it ``name``.

    Raises
    ------
    InputError
        Not a non-negative integer (``option="workers"``).
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        raise InputError(f"{name} must be a non-negative integer, got {workers!r}",
                         option="workers")
    return workers

@contextmanager
def worker_environment():
    """Single-threaded BLAS in the worker processes spawned inside this block (a variable the
    user has set is kept)."""
    saved = {k: os.environ.get(k) for k in WORKER_ENV}
    for k, v in WORKER_ENV.items():
        os.environ.setdefault(k, v)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _stop_tqdm_monitor() -> None:
    """End tqdm's monitor thread, which any progress bar starts (even a disabled one) and which
    otherwise sleeps on until the process exits; the next bar starts it again."""
    if "tqdm" not in sys.modules:
        return
    import threading

    from tqdm._monitor import TMonitor

    for t in threading.enumerate():
        if isinstance(t, TMonitor):
            t.exit()


#: matplotlib backends that draw off screen: a forked process may draw through them.
OFF_SCREEN_BACKENDS = ("agg", "pdf", "svg", "ps", "cairo",
                       "module://matplotlib_inline.backend_inline")


def fork_safe() -> bool:
    """Whether this process can be forked: on Linux, with no other Python thread running once
    tqdm's idle monitor is ended (a lock another thread holds at the fork would stay held in
    the child), and no matplotlib state of an on-screen backend (a GUI connection shared with
    the child)."""
    import threading

    if not sys.platform.startswith("linux"):
        return False
    if "matplotlib.pyplot" in sys.modules:  # (matplotlib is only looked at, not imported)
        if sys.modules["matplotlib"].get_backend().lower() not in OFF_SCREEN_BACKENDS:
            return False
    _stop_tqdm_monitor()
    return threading.active_count() == 1


def _worker_blas_threads() -> int:
    """The BLAS threads of a worker: what :func:`worker_environment` set (the user's value of
    its variables where set, else 1)."""
    for key in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
        try:
            return max(1, int(os.environ[key]))
        except (KeyError, ValueError):
            continue
    return 1


#: Whether this process is a worker of :func:`new_pool` (set by :func:`init_worker`), and
#: whether :func:`settle_worker` has run in it.
_WORKER = {"pool": False, "settled": False}


def settle_worker(load=None) -> None:
    """In a worker process of :func:`new_pool`, the first time it is called: ``load()``
    (imports of the libraries its tasks use, e.g. those of the figures) and then
    :func:`gc.freeze` of every object that exists: the modules outlive every task, and the
    collector's full collections would otherwise walk them again in each. Elsewhere (this
    process, a Dask worker) and later calls: nothing."""
    if not _WORKER["pool"] or _WORKER["settled"]:
        return
    _WORKER["settled"] = True
    if load is not None:
        load()
    gc.freeze()


def init_worker(parent: int | None = None, forked: bool = False) -> None:
    """Initializer of every worker process: Ctrl-C goes to the parent alone (which ends the
    workers), and on Linux the worker gets SIGTERM when its parent dies, even by SIGKILL. A
    ``forked`` worker also sets the BLAS it inherited, already loaded with the parent's
    threads, to the threads a spawned worker gets from the environment (one unless the user
    set another number), and freezes the objects it inherited (the libraries the parent had
    loaded, its data) out of the garbage collector (:func:`gc.freeze`): they outlive every
    task, and the collector's full collections would otherwise walk them again and again,
    touching (and so copying) pages the worker could share with its parent.

    ``parent`` is the process id of the parent that started the worker: a parent that died
    before the death signal was asked for (between the fork and the request) sends none, so
    the worker then ends here (it has been adopted by another process)."""
    import threading

    from tqdm import tqdm

    _WORKER["pool"] = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # tqdm's default lock is a multiprocessing semaphore; a worker ended by terminate() never
    # releases it and the resource tracker prints a warning at exit. A worker draws no bar
    # of its own, so a thread lock does.
    tqdm.set_lock(threading.RLock())
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: the parent's own cleanup must do
        pass
    if parent is not None and os.getppid() != parent:
        os._exit(1)
    if forked:  # the environment came too late for the BLAS loaded before the fork
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=_worker_blas_threads(), user_api="blas")
        gc.freeze()


def new_pool(workers: int, *, fork: bool = False):
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` spawned processes with
    :func:`init_worker`; create it inside :func:`worker_environment`.

    With ``fork``, the processes are forked from this one instead where :func:`fork_safe`
    holds when it is created (they start at the first task, before the executor starts its
    manager thread): each then has the libraries this process has loaded, where a spawned one
    imports them again, a cost that is not small next to a comparison's own work
    (BENCHMARKS.md, "Measurements behind design choices"). The workers are forked at the first
    task and hold copies of the descriptors open at that moment (an output directory's lock, if
    one were held then, until they end): only for pools that live within one call, started
    before any output is written, as :func:`lazy_process_pool` in ``compare``. ``fork_safe``
    counts Python threads: the BLAS's own threads cope with a fork (OpenBLAS re-creates its
    pool in the child).
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    method = "fork" if fork and fork_safe() else "spawn"
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(method),
                               initializer=init_worker,
                               initargs=(os.getpid(), method == "fork"))


def terminate(pool) -> None:
    """End a pool's worker processes now, without waiting for their tasks."""
    # ProcessPoolExecutor.shutdown waits for running tasks (minutes for a posterior);
    # Python 3.14 has terminate_workers(), 3.11 only the executor's own process table.
    processes = list((getattr(pool, "_processes", None) or {}).values())
    results = getattr(pool, "_result_queue", None)  # (shutdown forgets it)
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        try:
            p.terminate()
        except (OSError, ValueError, AttributeError):
            pass
    for p in processes:
        try:
            p.join(timeout=2)
        except (OSError, ValueError, AssertionError):
            pass
    # A worker ended while it was sending a result leaves the start of a message in the result
    # pipe, and the manager thread waits for the rest for as long as a writer is open, this
    # process's included (the interpreter's exit would then wait for that thread for ever).
    # The workers are gone: closing this process's end lets the thread read the pipe's end.
    writer = getattr(results, "_writer", None)
    if writer is not None:
        try:
            writer.close()
        except OSError:
            pass
    # The executor's manager thread sees the dead workers and releases the queues' semaphores;
    # without waiting for it, the resource tracker reports them as leaked at exit.
    manager = getattr(pool, "_executor_manager_thread", None)
    if manager is not None:
        manager.join(timeout=2)


@contextmanager
def process_pool(workers: int = 0, *, fork: bool = False):
    """Worker processes (spawn, one BLAS thread each) that :func:`~bayesfo.comparison.compare` and
    :func:`~bayesfo.output.write_outputs` can share through their ``pool`` argument: the
    figures are then drawn by processes that have already loaded the libraries.

    Parameters
    ----------
    workers : int
        Number of processes (0: one per CPU).
    fork : bool
        Fork the processes from this one at the first task where that is safe (see
        :func:`new_pool`): only for a pool that lives within one call, as :func:`executor`'s.

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor
        Its workers are ended at once if the block raises (Ctrl-C included).
    """
    check_workers(workers)
    with worker_environment():  # processes are spawned as tasks are submitted
        pool = new_pool(workers or available_cpus(), fork=fork)
        try:
            yield pool
        except BaseException:
            terminate(pool)
            raise
        pool.shutdown(wait=True)


@contextmanager
def single_blas_thread():
    """One BLAS thread in this process inside the block, as in the worker processes
    (threadpoolctl's limits on every BLAS loaded, restored afterwards).

    The matrices of a comparison are a few parameters wide: threads cannot speed them up, and on
    a busy machine OpenBLAS's spinning threads slow the optimiser's small factorisations several
    fold (BENCHMARKS.md, "Measurements behind design choices"). It also makes the arithmetic of
    this process that of the workers.
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield


class LazyPool:
    """A pool of worker processes (as :func:`process_pool`) that starts them at its first task.

    :func:`~bayesfo.comparison.compare` given such a pool runs each structure's quick steps in
    this process and submits only the long ones (see :mod:`bayesfo.comparison.schedule`); a
    comparison that has none never starts a process. Use it through :func:`lazy_process_pool`.
    """

    def __init__(self, workers: int, prepare=None):
        self.workers = workers
        self._pool = None
        self._prepare = prepare

    @property
    def started(self) -> bool:
        """Whether the worker processes have been started."""
        return self._pool is not None

    @property
    def prepared(self) -> bool:
        """Whether the pool's preparation (``prepare`` of :func:`lazy_process_pool`) has run,
        or there is none."""
        return self._prepare is None

    def prepare(self) -> None:
        """Run the pool's preparation now if it has not run: e.g. the imports that the
        workers, forked from this process, then share. The schedule calls it once it has
        started what needs no libraries (:mod:`bayesfo.comparison.early`); :meth:`start`
        calls it at the latest."""
        if self._prepare is not None:
            prepare, self._prepare = self._prepare, None
            prepare()

    def start(self):
        """The pool, started now if it was not (inside :func:`worker_environment`); its
        processes are forked from this one where :func:`fork_safe` (``new_pool(fork=True)``:
        the pool lives within the block of :func:`lazy_process_pool`, and is started at its
        first task, after which the executor starts its manager thread)."""
        if self._pool is None:
            self.prepare()
            self._pool = new_pool(self.workers, fork=True)
        return self._pool

    def submit(self, fn, /, *args, **kwargs):
        if self._pool is not None:
            return self._pool.submit(fn, *args, **kwargs)
        pool = self.start()
        with warnings.catch_warnings():
            # The first task forks the workers. Python 3.12+ warns at any fork of a process
            # with several OS threads; those here are the BLAS's idle threads, which cope
            # with a fork (fork_safe: no other Python thread runs).
            warnings.filterwarnings("ignore", message=".*multi-threaded.*fork",
                                    category=DeprecationWarning)
            return pool.submit(fn, *args, **kwargs)


@contextmanager
def lazy_process_pool(workers: int = 0, prepare=None):
    """A :class:`LazyPool` of ``workers`` processes (0: one per CPU): none is started until a
    task is submitted. ``prepare`` (optional, called once in this process before any process
    is forked, see :meth:`LazyPool.prepare`) is e.g. the import of the libraries the workers
    share. Like :func:`process_pool`, its workers are ended at once if the block raises
    (Ctrl-C included)."""
    check_workers(workers)
    with worker_environment():
        lazy = LazyPool(workers or available_cpus(), prepare)
        try:
            yield lazy
        except BaseException:
            if lazy.started:
                terminate(lazy._pool)
            raise
        if lazy.started:
            lazy._pool.shutdown(wait=True)


class InlineExecutor(Executor):
    """An executor that runs each task in this process as it is submitted (the serial path of
    :func:`executor`): the schedule that drives worker processes drives it the same way, so a
    comparison has one code path whatever the number of processes."""

    def submit(self, fn, /, *args, **kwargs):
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # handed to whoever reads the future, as a pool does
            if not isinstance(exc, Exception):
                raise
            future.set_exception(exc)
        return future


def runs_here(pool) -> bool:
    """Whether the tasks of ``pool`` (or some of them) compute in this process: an
    :class:`InlineExecutor`, or a :class:`LazyPool`, whose schedule keeps the quick steps
    here. This process then limits its BLAS to one thread (:func:`single_blas_thread`)."""
    return isinstance(pool, (InlineExecutor, LazyPool))


@contextmanager
def executor(workers: int, n_tasks: int | None = None, prepare=None):
    """The executor of a job that asks for ``workers`` processes: 0, the automatic choice (a
    :class:`LazyPool` of one process per CPU, started only when a task needs it); 1 (or a job of
    one task), this process (:class:`InlineExecutor`); more, a :func:`process_pool` of that many
    processes, at most one per task, forked where safe (they then share what ``prepare``
    loaded instead of importing it again). ``prepare`` (optional) is called once in this process
    before any task runs or process starts: by the :class:`LazyPool` when its user says
    (:meth:`LazyPool.prepare`), else at once.

    Yields
    ------
    concurrent.futures.Executor or LazyPool
    """
    check_workers(workers)
    n = min(workers or available_cpus(), n_tasks or available_cpus())
    if workers == 0:
        with lazy_process_pool(n, prepare) as pool:
            yield pool
        return
    if prepare is not None:
        prepare()
    if n <= 1:
        yield InlineExecutor()
    else:
        with process_pool(n, fork=True) as pool:
            yield pool


def cpu_times() -> tuple[float, float, int] | None:
    """(idle, total, CPUs) time so far, in clock ticks (``/proc/stat``), of the CPUs this
    process may run on (its affinity set: under taskset, a cpuset or a batch scheduler, idle
    CPUs outside it are no use); ``None`` where the system does not tell."""
    try:
        allowed = os.sched_getaffinity(0)
    except (AttributeError, OSError):
        allowed = None
    idle = total = 0.0
    count = 0
    try:
        with open("/proc/stat") as f:
            for line in f:
                name, _, rest = line.partition(" ")
                if not name.startswith("cpu") or name == "cpu":
                    continue
                if allowed is not None and int(name[3:]) not in allowed:
                    continue
                fields = [float(x) for x in rest.split()]
                if len(fields) < 4:
                    return None
                idle += fields[3] + (fields[4] if len(fields) > 4 else 0.0)  # idle + iowait
                total += sum(fields[:8])
                count += 1
    except (OSError, ValueError):
        return None
    return (idle, total, count) if count else None


def idle_cpus(since) -> float | None:
    """CPUs of this process's set left idle on average since ``since`` (from
    :func:`cpu_times`)."""
    now = cpu_times()
    if since is None or now is None or now[2] != since[2] or now[1] <= since[1]:
        return None
    return now[2] * (now[0] - since[0]) / (now[1] - since[1])


#: Idle CPUs during a job from which its figures are drawn in two processes.
SPARE_CPU_FOR_FIGURES = 0.5


def figure_processes(since) -> int:
    """2 when a second process can draw figures beside this one: two CPUs or more, and at
    least :data:`SPARE_CPU_FOR_FIGURES` of them idle since ``since`` (:func:`cpu_times`). On a
    busy machine the two processes would share one core and take longer than one
    (BENCHMARKS.md, "Measurements behind design choices")."""
    if available_cpus() < 2:
        return 1
    idle = idle_cpus(since)
    return 2 if idle is not None and idle >= SPARE_CPU_FOR_FIGURES else 1


#: Idle CPUs over the last :data:`SPARE_CHECK` seconds for a worker to borrow one for a helper
#: process (:class:`Helper`): most of a CPU, so that a helper never shares a busy core.
SPARE_CPU_FOR_HELPER = 0.8
#: Seconds between a worker's looks at the idle CPUs (:class:`SpareCPU`).
SPARE_CHECK = 0.05


class SpareCPU:
    """Whether a CPU has been idle of late, for a worker process of a pool that could hand part
    of its work to a helper (:class:`Helper`): :meth:`now` is True once at least
    :data:`SPARE_CPU_FOR_HELPER` of a CPU was idle over the last :data:`SPARE_CHECK` seconds (or
    more). Only in a pool's worker (never in a process the user runs alone, nor with
    ``--workers 1``), with two CPUs or more, and where forking is safe."""

    def __init__(self):
        import time

        self._clock = time.monotonic
        self.usable = (_WORKER["pool"] and available_cpus() >= 2 and fork_safe()
                       and cpu_times() is not None)
        self._since, self._at = (cpu_times(), self._clock()) if self.usable else (None, 0.0)

    def now(self) -> bool:
        if not self.usable or self._clock() - self._at < SPARE_CHECK:
            return False
        idle = idle_cpus(self._since)
        self._since, self._at = cpu_times(), self._clock()
        return idle is not None and idle >= SPARE_CPU_FOR_HELPER


class Helper:
    """``fn()`` run in a process forked from this one now, its return value sent back
    (pickled) through a pipe: :meth:`result` waits for it. The helper ignores Ctrl-C and ends
    when this process dies, as a worker does; it never runs this process's exit handlers.

    Use it for work whose result does not depend on where it runs; :meth:`result` returns
    None where the helper failed (raised, died, could not send), and the caller then does the
    work itself."""

    def __init__(self, fn):
        import pickle

        read, write = os.pipe()
        parent = os.getpid()
        pid = os.fork()
        if pid == 0:  # the helper
            code = 1
            try:
                os.close(read)
                init_worker(parent)  # Ctrl-C ignored; ends with this process
                data = pickle.dumps(fn(), protocol=pickle.HIGHEST_PROTOCOL)
                with os.fdopen(write, "wb") as out:
                    out.write(data)
                code = 0
            except BaseException:  # noqa: BLE001  (the caller does the work itself)
                pass
            finally:
                os._exit(code)
        os.close(write)
        self._pid, self._read = pid, read

    def result(self):
        """The helper's return value, or None where it failed."""
        import pickle

        try:
            with os.fdopen(self._read, "rb") as pipe:
                data = pipe.read()
        finally:
            _, status = os.waitpid(self._pid, 0)
            self._pid = None  # reaped: its number may be another process's from now on
        if status != 0 or not data:
            return None
        try:
            return pickle.loads(data)
        except Exception:  # noqa: BLE001
            return None

    def stop(self) -> None:
        """End the helper now (its result is not wanted)."""
        if self._pid is None:  # already reaped by result()
            return
        try:
            os.kill(self._pid, signal.SIGKILL)
            os.waitpid(self._pid, 0)
        except (ProcessLookupError, ChildProcessError):
            pass
        try:
            os.close(self._read)
        except OSError:
            pass
