"""A comparison's steps as pool tasks (bayesfo.comparison.schedule): a structure's noise
models still in the running are sampled side by side, with the numbers, the warnings and the errors of the serial
path."""

from __future__ import annotations

import json
import os
import warnings
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from fresh_process import in_fresh_process

import bayesfo as bf
import bayesfo.comparison.schedule as schedule
import bayesfo.comparison.steps as steps
from bayesfo import parallel
from bayesfo.errors import InputError
from bayesfo.parallel import LazyPool, lazy_process_pool

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
#: On this isotherm the screen decides neither structure's noise model: zener-int's three and
#: maxwell-int's proportional and relative_parts are sampled (its constant trails by 5 nats and
#: is set aside; by importance sampling, about half a second each).
BOTH = "zener-int,maxwell-int"
#: The noise models sampled for each structure of BOTH (the others are set aside by the screen).
SAMPLED = {"zener-int": ("constant", "proportional", "relative_parts"),
           "maxwell-int": ("proportional", "relative_parts")}


def _compare(structures=BOTH, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = bf.compare(bf.read(DATA), structures, seed=2, progress=False, **kw)
    return result, [(w.category, str(w.message)) for w in caught]


def _numbers(results) -> dict:
    out = {}
    for r in results:
        c = r.criteria
        out[r.name] = (r.log_z, r.log_z_err, c.loo, c.waic, c.noise_models["chosen"],
                       {k: m["log_evidence"] for k, m in c.noise_models["models"].items()},
                       r.posterior.samples.mean(axis=0).tolist())
    return out


def test_one_and_two_workers_give_the_same_numbers():
    one, caught_one = _compare(workers=1)
    two, caught_two = _compare(workers=2)
    for r in one.results:  # several noise models sampled: the case the schedule splits
        models = r.criteria.noise_models["models"]
        assert set(models) == set(steps.NOISE_CANDIDATES)
        assert {n for n, m in models.items() if m["log_evidence_err"] is not None} == \
            set(SAMPLED[r.name])
    assert _numbers(one.results) == _numbers(two.results)
    assert json.dumps(one.to_summary(), sort_keys=True, default=str) == \
        json.dumps(two.to_summary(), sort_keys=True, default=str)
    assert caught_one == caught_two


class _Recorder:
    """An executor (one thread, in this process: monkeypatches apply) that records which step
    each task runs."""

    def __init__(self):
        self.pool = ThreadPoolExecutor(1)
        self.steps = []

    def submit(self, fn, *args):
        self.steps.append((args[0].__name__, args[1].name,
                           args[3] if args[0].__name__ == "sample_held" else None))
        return self.pool.submit(fn, *args)


@pytest.fixture
def noisy_sampler(monkeypatch):
    """Each posterior warns which noise model it ran under."""
    sample = steps.sample

    def warning_sample(s, data, noise, fit, options):
        warnings.warn(f"{s.name}: sampled under {noise} noise", UserWarning, stacklevel=1)
        return sample(s, data, noise, fit, options)

    monkeypatch.setattr(steps, "sample", warning_sample)


def test_a_pool_keeps_the_warnings_of_the_serial_path(noisy_sampler):
    serial, caught_serial = _compare(workers=1)
    recorder = _Recorder()
    pooled, caught_pooled = _compare(pool=recorder)
    recorder.pool.shutdown()
    assert _numbers(serial.results) == _numbers(pooled.results)
    assert caught_serial == caught_pooled
    for r in pooled.results:
        record = r.criteria.noise_models
        # Only the chosen model's warning reaches the user; the others' are in their records.
        assert (UserWarning, f"{r.name}: sampled under {record['chosen']} noise") in caught_pooled
        for other in SAMPLED[r.name]:
            if other == record["chosen"]:
                continue
            assert (UserWarning, f"{r.name}: sampled under {other} noise") not in caught_pooled
            assert record["models"][other]["warnings"][0] == \
                f"{r.name}: sampled under {other} noise"
    assert sorted(recorder.steps) == sorted(
        [("_first", s, None) for s in ("zener-int", "maxwell-int")]
        + [("sample_held", s, n) for s in ("zener-int", "maxwell-int") for n in SAMPLED[s]]
        + [("conclude", s, None) for s in ("zener-int", "maxwell-int")])


@pytest.fixture
def failing_steps(monkeypatch):
    """zener-int's optimisation and maxwell-int's posterior under proportional noise raise an
    InputError."""
    fit_structure, sample = steps.fit_structure, steps.sample

    def failing_fit(structure, *args, **kwargs):
        if structure.name == "zener-int":
            raise InputError("no fit here")
        return fit_structure(structure, *args, **kwargs)

    def failing_sample(s, data, noise, fit, options):
        if s.name == "maxwell-int" and noise == "proportional":
            raise InputError("no posterior here")
        return sample(s, data, noise, fit, options)

    monkeypatch.setattr(steps, "fit_structure", failing_fit)
    monkeypatch.setattr(steps, "sample", failing_sample)


def test_an_input_error_in_a_step_ends_that_structure_alone(failing_steps):
    structures = BOTH + ",voigt-int"
    serial, _ = _compare(structures, workers=1)
    recorder = _Recorder()
    pooled, _ = _compare(structures, pool=recorder)
    recorder.pool.shutdown()
    for result in (serial, pooled):
        assert result["zener-int"].error == "no fit here"
        assert result["maxwell-int"].error == "no posterior here"
        assert result["voigt-int"].error is None
    assert _numbers([serial["voigt-int"]]) == _numbers([pooled["voigt-int"]])
    # A structure whose fit failed has no posterior to wait for; one whose posterior failed
    # has no conclusion.
    assert [st for st in recorder.steps if st[1] == "zener-int"] == [("_first", "zener-int", None)]
    assert ("conclude", "maxwell-int", None) not in recorder.steps


# ------------------------------------------------ the automatic schedule (workers=0)
class _LazyRecorder(LazyPool):
    """A LazyPool that runs each task at once in this process and thread (monkeypatches apply;
    warnings are caught as in a worker of its own), recording which step each task runs."""

    def __init__(self):
        super().__init__(1)
        self.steps = []

    def submit(self, fn, /, *args):
        self.steps.append((args[0].__name__, args[1].name,
                           args[3] if args[0].__name__ == "sample_held" else None))
        future = Future()
        future.set_result(fn(*args))
        return future


def test_the_automatic_schedule_gives_the_numbers_of_the_serial_path(noisy_sampler):
    serial, caught_serial = _compare(workers=1)
    auto, caught_auto = _compare(workers=0)
    assert _numbers(serial.results) == _numbers(auto.results)
    assert json.dumps(serial.to_summary(), sort_keys=True, default=str) == \
        json.dumps(auto.to_summary(), sort_keys=True, default=str)
    assert caught_serial == caught_auto


def test_quick_posteriors_run_here_and_start_no_process():
    """Both noise models of both structures are certified by importance sampling: the screen
    promises it, and no worker process is started."""
    serial, caught_serial = _compare(workers=1)
    with lazy_process_pool(2) as pool:
        auto, caught_auto = _compare(pool=pool)
        assert not pool.started
    assert _numbers(serial.results) == _numbers(auto.results)
    assert caught_serial == caught_auto


def _no_promise_for(monkeypatch, name: str) -> None:
    """The screen of structure ``name`` promises no quick posterior (its steps then go to the
    pool); the step is recorded as ``pessimistic``."""
    probe = schedule.fit_and_probe

    def pessimistic(s, data, options, *fitted):
        prepared, quick = probe(s, data, options, *fitted)
        return prepared, quick and s.name != name

    monkeypatch.setattr(schedule, "fit_and_probe", pessimistic)


def _steps_in_pool(pool) -> list:
    """The steps ``pool`` ran (sorted), after checking that the comparison through it gives the
    numbers and warnings of the serial path."""
    serial, caught_serial = _compare(workers=1)
    auto, caught_auto = _compare(pool=pool)
    assert _numbers(serial.results) == _numbers(auto.results)
    assert caught_serial == caught_auto
    return sorted(pool.steps)


def test_structures_without_the_promise_go_to_the_pool(monkeypatch, noisy_sampler):
    """A structure whose screen does not promise a quick posterior has its posteriors and its
    conclusion run by the pool, with the numbers and warnings of the serial path; the others
    run here."""
    _no_promise_for(monkeypatch, "maxwell-int")
    assert _steps_in_pool(_LazyRecorder()) == [
        ("conclude", "maxwell-int", None),
        *(("sample_held", "maxwell-int", n) for n in SAMPLED["maxwell-int"])]


class _StartingRecorder(_LazyRecorder):
    """A :class:`_LazyRecorder` of two workers that counts as started from its first task, as
    a :class:`LazyPool` does."""

    def __init__(self):
        super().__init__()
        self.workers = 2

    @property
    def started(self) -> bool:
        return bool(self.steps)


def test_once_the_workers_have_started_every_step_still_to_come_goes_to_them(monkeypatch,
                                                                           noisy_sampler):
    """The first structure (the larger) starts the workers; the other's fit, queued here
    before they started, and every later step then run in the workers, with the numbers and
    warnings of the serial path."""
    _no_promise_for(monkeypatch, "zener-int")
    # Step (1) runs as schedule._probe (fit_and_probe, here the pessimistic stand-in, with the
    # best fits of the evidence bound).
    assert _steps_in_pool(_StartingRecorder()) == [
        ("_probe", "maxwell-int", None),
        ("conclude", "maxwell-int", None),
        ("conclude", "zener-int", None),
        *(("sample_held", s, n) for s in ("maxwell-int", "zener-int") for n in SAMPLED[s])]


def test_free_workers_take_the_long_posteriors_first():
    """Steps waiting for a worker go out by rank, in the order they came within a rank: the
    posteriors without the quick promise, then the fits, then quick posteriors and
    conclusions."""
    import heapq
    import itertools

    order = itertools.count()
    came = [("conclude", True), ("constant", True), ("first", True), ("proportional", False),
            ("first", False), ("constant", False), ("conclude", False)]
    waiting = []
    for what, quick in came:
        heapq.heappush(waiting, (schedule._rank(what, quick=quick), next(order), what, quick))
    out = [heapq.heappop(waiting)[2:] for _ in came]
    assert out == [("proportional", False), ("constant", False), ("first", True),
                   ("first", False), ("conclude", True), ("constant", True),
                   ("conclude", False)]


def test_with_one_worker_the_quick_steps_stay_here(monkeypatch, noisy_sampler):
    """A pool of one worker (a machine with one CPU) takes only the long structure's steps:
    handing it the others would only add the shipping."""
    _no_promise_for(monkeypatch, "zener-int")
    pool = _StartingRecorder()
    pool.workers = 1
    _compare(pool=pool)
    assert sorted(pool.steps) == [("conclude", "zener-int", None),
                                  *(("sample_held", "zener-int", n) for n in SAMPLED["zener-int"])]


def test_an_input_error_ends_that_structure_alone_on_the_automatic_schedule(failing_steps):
    auto, _ = _compare(BOTH + ",voigt-int", workers=0)
    assert auto["zener-int"].error == "no fit here"
    assert auto["maxwell-int"].error == "no posterior here"
    serial, _ = _compare("voigt-int", workers=1)
    assert _numbers([serial["voigt-int"]]) == _numbers([auto["voigt-int"]])


def test_one_blas_thread_inside_the_block_and_the_count_restored_after():
    from threadpoolctl import threadpool_info

    def counts():
        return [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]

    before = counts()
    if not before:
        pytest.skip("no BLAS library found in this process")
    with parallel.single_blas_thread():
        assert counts() == [1] * len(before)
    assert counts() == before


_MARK = {"set_in_parent": False}


def _worker_state():
    """In a worker: whether it has the parent's memory (a fork), its BLAS thread counts and
    the number of objects frozen out of its garbage collector."""
    import gc

    from threadpoolctl import threadpool_info

    return _MARK["set_in_parent"], [p["num_threads"] for p in threadpool_info()
                                    if p["user_api"] == "blas"], gc.get_freeze_count()


def test_the_automatic_schedule_forks_its_workers_where_safe(monkeypatch):
    """The automatic schedule's workers are forked where that is safe (they then share the
    libraries this process has loaded instead of importing them again) and run one BLAS
    thread each, as spawned ones do. A forked worker freezes what it inherited (every
    module this process has loaded) out of its garbage collector; this process's collector
    is left as it was."""
    import gc

    if not parallel.fork_safe():
        pytest.skip("another thread runs in this process (e.g. left by a Dask test)")
    monkeypatch.setitem(_MARK, "set_in_parent", True)
    before = gc.get_freeze_count()
    with lazy_process_pool(2) as pool:
        forked, blas, frozen = pool.submit(_worker_state).result()
        assert pool._pool._mp_context.get_start_method() == "fork"
    assert forked
    assert blas and set(blas) == {1}
    # numpy, scipy and the package alone are tens of thousands of tracked objects
    assert frozen > max(10_000, before)
    assert gc.get_freeze_count() == before


def test_the_automatic_schedule_spawns_while_another_thread_runs(monkeypatch):
    import threading

    monkeypatch.setitem(_MARK, "set_in_parent", True)
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert not parallel.fork_safe()
        with lazy_process_pool(1) as pool:
            forked, blas, frozen = pool.submit(_worker_state).result()
            assert pool._pool._mp_context.get_start_method() == "spawn"
    finally:
        stop.set()
        other.join()
    assert not forked and frozen == 0
    assert blas and set(blas) == {1}


def test_a_worker_whose_parent_died_before_it_started_ends_itself():
    """The death signal covers a parent dying after the worker asked for it; one that died
    between the fork and the request sends none, so the worker checks its parent itself."""
    import subprocess
    import sys

    code = ("import os; from bayesfo.parallel import init_worker; "
            "init_worker(os.getppid() + 10**7); print('still running')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 1 and "still running" not in done.stdout
    code = "import os; from bayesfo.parallel import init_worker; init_worker(os.getppid()); print('ok')"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "ok"


def test_a_forked_worker_freezes_what_it_inherited():
    """init_worker of a forked worker freezes the objects it inherited out of its garbage
    collector (a spawned one has inherited nothing); run in a fresh process, as this one may
    hold threads that make the suite's pools spawn."""
    import subprocess
    import sys

    code = ("import gc, os; import numpy; from bayesfo.parallel import init_worker; "
            "init_worker(os.getppid(), forked={}); print(gc.get_freeze_count())")
    counts = {}
    for forked in (True, False):
        done = subprocess.run([sys.executable, "-c", code.format(forked)], capture_output=True,
                              text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        counts[forked] = int(done.stdout)
    assert counts[False] == 0
    assert counts[True] > 10_000  # numpy and the package's modules


_POOLS_SCRIPT = '''
import numpy  # the BLAS, loaded before any fork
from threadpoolctl import threadpool_info

MARK = []


def state():
    return bool(MARK), sorted({p["num_threads"] for p in threadpool_info()
                               if p["user_api"] == "blas"})


if __name__ == "__main__":
    MARK.append(1)  # set in this process only: a forked worker has it, a spawned one not
    from bayesfo.parallel import executor, lazy_process_pool, process_pool

    with lazy_process_pool(1) as pool:
        print("lazy", *pool.submit(state).result())
    with process_pool(1) as pool:
        print("process_pool", *pool.submit(state).result())
    with executor(2, 2, prepare=lambda: MARK.append(2)) as pool:  # --workers 2
        print("executor", *pool.submit(state).result(), MARK == [1, 2])
'''


@pytest.mark.parametrize("blas_env, threads", [(None, 1), ("2", 2)])
def test_pool_workers_in_a_fresh_command(tmp_path, blas_env, threads):
    """In a fresh process (as the command line runs), the automatic schedule's pool and the
    pool of an explicit number of workers (prepared first) fork their workers, and a
    process_pool spawns them by default; all run the BLAS threads of the worker environment:
    one, or the number the user set."""
    import os
    import subprocess
    import sys

    script = tmp_path / "pools.py"
    script.write_text(_POOLS_SCRIPT)
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")}
    if blas_env is not None:
        env["OPENBLAS_NUM_THREADS"] = blas_env
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"lazy True [{threads}]",
                                        f"process_pool False [{threads}]",
                                        f"executor True [{threads}] True"]


class _KillingPool:
    """A pool whose first task ends its worker process (as the kernel's OOM killer would): the
    pool is then broken for every task still waiting and every later one."""

    def __init__(self, pool):
        self.pool, self.killed = pool, False

    def submit(self, fn, *args):
        if not self.killed:
            self.killed = True
            import os

            return self.pool.submit(os._exit, 1)
        return self.pool.submit(fn, *args)


def test_a_worker_that_dies_loses_no_structure():
    """compare with a pool whose worker dies: every structure is still run (the lost tasks in
    this process), with the numbers of the serial path, and a warning says what happened."""
    from bayesfo.parallel import process_pool

    data = bf.read(Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
                   / "Tp020C.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)
        serial = bf.compare(data, "voigt,zener", seed=0, progress=False, workers=1)
        with process_pool(2) as pool, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            broken = bf.compare(data, "voigt,zener", seed=0, progress=False,
                                pool=_KillingPool(pool))
    assert any("a worker process ended unexpectedly" in str(w.message) for w in caught)
    assert broken.ranking == serial.ranking
    for name in serial.ranking:
        a, b = serial[name], broken[name]
        assert b.error is None
        np.testing.assert_array_equal(a.posterior.samples, b.posterior.samples)
        assert a.criteria.evidence.log_z == b.criteria.evidence.log_z


def test_figures_are_drawn_here_when_a_worker_dies(tmp_path):
    from bayesfo.parallel import process_pool
    from bayesfo.plotting import write_figures

    data = bf.read(Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp"
                   / "Tp020C.csv")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)
        result = bf.compare(data, "voigt", seed=0, progress=False, workers=1)
    with process_pool(1) as pool:
        written = write_figures(result, tmp_path, pool=_KillingPool(pool))
    traced = {"trace_voigt"} if result["voigt"].posterior.sampler != "importance" else set()
    assert set(written) == {"ranking", "bode", "moduli", "time_functions", "nyquist",
                            "residuals", "q_posteriors", "corner_voigt"} | traced
    assert all(p.stat().st_size > 0 for paths in written.values() for p in paths)


def _collector_state():
    import gc
    import sys

    return gc.get_freeze_count(), "arviz_stats" in sys.modules


def test_a_spawned_worker_settles_at_its_first_step():
    """A spawned worker (``--workers 2``) loads the ArviZ libraries at its first step and
    freezes what it has loaded out of its garbage collector, as a forked one does at start."""
    from bayesfo.comparison.schedule import _task
    from bayesfo.parallel import new_pool, worker_environment

    with worker_environment():
        pool = new_pool(1)
        try:
            before = pool.submit(_collector_state).result(timeout=120)
            assert pool.submit(_task, int).result(timeout=120) == (0, None, [])
            after = pool.submit(_collector_state).result(timeout=120)
        finally:
            pool.shutdown(wait=True)
    assert before == (0, False)
    assert after[1] and after[0] > 50_000  # numpy, scipy, xarray, ArviZ


class _Taken(schedule.EarlyFits):
    """EarlyFits that records what the schedule took: (structure, waited, got an optimum)."""

    taken: list = []

    def take(self, name, *, wait):
        fitted = super().take(name, wait=wait)
        self.taken.append((name, wait, fitted is not None))
        return fitted


def _early_fits(overtaken: bool):
    """In a fresh process (no thread left by other tests, so that forking is safe): the
    comparison through a pool to prepare, every optimisation warning which structure it
    fitted wherever it runs, the early optimisations recorded (:class:`_Taken`). With
    ``overtaken``, zener-int promises no quick posterior (its steps start the workers: a
    :class:`_StartingRecorder`) and the early process is stuck on maxwell-int. Returns (what
    was taken, what the serial path took, the preparations seen, whether the numbers and the
    warnings are the serial path's, the pool's steps, the structures optimised in this
    process)."""
    import time

    import bayesfo.comparison.early as early

    assert parallel.fork_safe()
    fit = steps._fit

    def warning_fit(s, data, options):
        warnings.warn(f"{s.name}: optimised", UserWarning, stacklevel=1)
        if os.getpid() == parent:
            here.append(s.name)
        elif overtaken and s.name == "maxwell-int":
            time.sleep(120)  # the early process never delivers it
        return fit(s, data, options)

    parent, here = os.getpid(), []
    steps._fit = early._fit = warning_fit
    schedule.EarlyFits = _Taken
    serial, caught_serial = _compare(workers=1)
    taken_serial = list(_Taken.taken)
    del here[:]
    assert (UserWarning, "zener-int: optimised") in caught_serial
    prepared = []
    if overtaken:
        probe = schedule.fit_and_probe
        schedule.fit_and_probe = lambda s, *args: (
            lambda out: (out[0], out[1] and s.name != "zener-int"))(probe(s, *args))
        pool = _StartingRecorder()
        pool._prepare = lambda: prepared.append(len(_Taken.taken))
        auto, caught_auto = _compare(pool=pool)
        ran = sorted(pool.steps)
    else:
        with lazy_process_pool(2, prepare=lambda: prepared.append(len(_Taken.taken))) as pool:
            auto, caught_auto = _compare(pool=pool)
            ran = pool.started
    same = (_numbers(serial.results) == _numbers(auto.results)
            and json.dumps(serial.to_summary(), sort_keys=True, default=str)
            == json.dumps(auto.to_summary(), sort_keys=True, default=str)
            and caught_serial == caught_auto)
    return list(_Taken.taken), taken_serial, prepared, same, ran, here


def test_the_optimisations_begin_in_a_process_forked_before_the_libraries_load():
    """With a pool to prepare (the command's: the libraries load then), the optimisations run
    in a forked process meanwhile; the structures take them from it, with the numbers and
    warnings (the optimisations' included) of the serial path."""
    taken, taken_serial, prepared, same, started, here = in_fresh_process(_early_fits, False)
    assert taken_serial == []  # the serial path forks nothing
    assert prepared == [0]  # once, before any structure was taken up
    assert taken == [("zener-int", True, True), ("maxwell-int", True, True)]
    assert here == []  # both optima came from the early process
    assert same and not started


def test_workers_that_overtake_the_early_optimisations_end_them():
    """Once the workers have started, a structure whose optimum has not come is optimised by
    the worker, and the early process (here stuck on it) is ended: same numbers."""
    taken, _, prepared, same, ran, here = in_fresh_process(_early_fits, True)
    assert prepared == [0]
    assert taken == [("zener-int", True, True), ("maxwell-int", False, False)]
    assert here == ["maxwell-int"]  # by the (here: in-process) worker
    assert same and ("_probe", "maxwell-int", None) in ran


@pytest.mark.parametrize("set_aside, recorder", [(True, _LazyRecorder), (False, _Recorder)])
def test_a_deferred_noise_model_waits_for_the_leaders_ln_z(monkeypatch, set_aside, recorder):
    """Where the screen defers a noise model (:func:`~bayesfo.comparison.steps.settle`), the
    leader's posterior runs first, and the other's only where its bound does not set it aside
    (forced here by a margin no bound meets), on the automatic schedule and a plain pool with
    the numbers of the serial path."""
    from test_noise_choice import springpot_data

    if not set_aside:
        monkeypatch.setattr(steps, "NOISE_SCREEN_MARGIN", np.inf)
    data, name = springpot_data(), "fractional_kelvin_voigt"

    def run(**kw):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return bf.compare(data, name, seed=3, progress=False, **kw)

    serial = run(workers=1)
    pool = recorder()
    result = run(pool=pool)
    if isinstance(pool, _Recorder):
        pool.pool.shutdown()
    ran = [step for step in pool.steps if step[0] == "sample_held"]
    assert ran[0] == ("sample_held", name, "constant")
    if not set_aside:  # the deferred ones after the leader
        assert sorted(ran[1:]) == [("sample_held", name, n)
                                   for n in ("proportional", "relative_parts")]
    else:
        assert ran == [("sample_held", name, "constant")]
    assert _numbers(serial.results) == _numbers(result.results)
    assert json.dumps(serial.to_summary(), sort_keys=True, default=str) == \
        json.dumps(result.to_summary(), sort_keys=True, default=str)
    method = serial[name].criteria.noise_models["models"]["proportional"]["evidence_method"]
    assert (method == steps.BOUND_METHOD) == set_aside
