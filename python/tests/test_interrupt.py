"""Ctrl-C (a notebook's ■) stops every long call within a second or two with
KeyboardInterrupt — never a PanicException — and keeps what had a meaning: a run's
samples so far, a sweep's rows, an identification's best point. The work limits of
the command line hold on every call: a request of hours is refused at once.

Python's own SIGINT handler is installed for each test: a shell that starts a job in
the background without job control has it ignore SIGINT, and Python then leaves it
ignored (a notebook's kernel has the handler)."""

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
import warnings

import numpy as np
import pytest

import rtid

WORM = "fixtures/worm-gear/frequency_response.json"
EMPS = "fixtures/real/emps/emps_estimation.json"
AXIS = "fixtures/real/emps/axis.json"


@contextlib.contextmanager
def ctrl_c_after(seconds: float):
    """Sends SIGINT to this process `seconds` after entering; yields the timer's
    start, so the caller can time how long the call took to stop."""
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    started = time.perf_counter()
    timer.start()
    try:
        yield started
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, inherited)


def stopped_within(started: float, after: float, limit: float = 2.0) -> float:
    """Seconds from the signal to now, checked below `limit`."""
    late = time.perf_counter() - started - after
    assert late < limit, f"stopped {late:.2f} s after Ctrl-C"
    return late


def test_ctrl_c_stops_a_simulation_and_keeps_its_samples():
    p = rtid.params("worm-gear")
    with pytest.raises(KeyboardInterrupt) as e, ctrl_c_after(0.5) as started:
        # 10 minutes simulated: about a minute of work.
        rtid.simulate(p, "sine:freq_hz=230,amp_nm=5", duration_s=600.0, sample_s=1e-2)
    stopped_within(started, 0.5)
    run = e.value.result
    t = run["time_s"]
    assert 0 < t[-1] < 600.0 and t.size == run["table_angle_rad"].size
    # The samples kept are the run's: the same as a run that short.
    whole = rtid.simulate(p, "sine:freq_hz=230,amp_nm=5", duration_s=0.2, sample_s=1e-2)
    n = whole["time_s"].size
    assert all(np.array_equal(run[k][:n], whole[k]) for k in whole)


def test_ctrl_c_stops_a_virtual_test():
    p = rtid.params("worm-gear")
    with pytest.raises(KeyboardInterrupt), ctrl_c_after(0.5) as started:
        rtid.run_experiment("torque-curve", p, period_s=300.0)
    stopped_within(started, 0.5)


def test_ctrl_c_stops_a_sweep_which_resumes_from_its_file(tmp_path):
    # 48 points in batches of 8 (the kernel's lanes), two at a time: Ctrl-C once the
    # first rows are in, while the others run.
    p = rtid.params("worm-gear")
    out = tmp_path / "sweep.csv"
    vary = ["Kw=2e5..4e5:6", "Kg=600..1100:8"]
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    timers = []

    def progress(done, total):
        if done and not timers:
            timers.append(time.perf_counter())
            os.kill(os.getpid(), signal.SIGINT)

    try:
        with pytest.raises(KeyboardInterrupt) as e:
            rtid.sweep(p, vary, "torque_rms", out=out, progress=progress)
    finally:
        signal.signal(signal.SIGINT, inherited)
    assert timers, "no row was reported"
    assert time.perf_counter() - timers[0] < 2.0
    partial = e.value.result
    assert isinstance(partial, rtid.SweepResult) and 0 < len(partial.index) < 48
    assert partial.design.shape == (len(partial.index), 2) and np.isfinite(partial.outputs).all()
    done = rtid.sweep(p, vary, "torque_rms", out=out, resume=True, progress=False)
    assert len(done.index) == 48
    for i, row in zip(partial.index, partial.outputs):
        assert np.array_equal(done.outputs[list(done.index).index(i)], row)


def test_a_keyboard_interrupt_inside_the_progress_bar_keeps_the_best_point(root):
    # A notebook's interrupt lands where Python runs: often inside tqdm's refresh. A
    # search of minutes (Nelder–Mead, each evaluation a replay of the EMPS trace).
    calls = []

    def progress(done, budget, evaluations):
        calls.append(done)
        if len(calls) == 2:
            raise KeyboardInterrupt

    with pytest.warns(RuntimeWarning, match="interrupted"):
        fit = rtid.identify(root / EMPS, rtid.params(path=root / AXIS), method="nelder-mead",
                            max_iters=5000, progress=progress)
    assert fit.interrupted and not fit.success and len(calls) >= 2
    assert fit.nfev < 5000 and all(np.isfinite(v) for v in fit.values.values())


def test_ctrl_c_during_the_bootstrap_keeps_the_fit_and_its_replicates(root):
    with pytest.warns(RuntimeWarning, match="interrupted"), ctrl_c_after(2.0):
        fit = rtid.identify(root / WORM, rtid.params("worm-gear"), fit="Kw,Kg", model="linear",
                            resample=2000)
    assert fit.interrupted
    assert all(np.isfinite(v) for v in fit.values.values())
    if fit.resampling is not None:
        assert fit.resampling["asked"] == 2000 and fit.resampling["fitted"] < 2000


def test_a_request_of_hours_is_refused_at_once():
    p = rtid.params("worm-gear")
    for kind, settings in [("torque-curve", dict(period_s=1e7)), ("torque-curve", dict(periods=1e6)),
                           ("fluctuation", dict(speed_deg_per_min=1e-3))]:
        started = time.perf_counter()
        with pytest.raises(ValueError, match="over the limit of 3600"):
            rtid.run_experiment(kind, p, **settings)
        assert time.perf_counter() - started < 5.0


def test_an_interrupt_of_a_fresh_process_is_a_keyboard_interrupt_not_a_panic():
    # The first call of a fresh interpreter, interrupted: NumPy's C API was imported
    # lazily at the first array, and a pending interrupt made that import panic.
    code = ("import os, signal, threading, rtid\n"
            "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
            "threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT)).start()\n"
            "try:\n"
            "    rtid.simulate(rtid.params('worm-gear'), 'sine:freq_hz=230,amp_nm=5', 600.0, sample_s=1.0)\n"
            "except KeyboardInterrupt:\n"
            "    print('KeyboardInterrupt')\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert run.stdout.strip() == "KeyboardInterrupt", run.stderr
    assert "PanicException" not in run.stderr and "panicked" not in run.stderr, run.stderr


def test_ctrl_c_at_the_start_of_a_search_is_a_keyboard_interrupt_or_its_first_point(root):
    # Stopped before the first evaluation there is nothing to keep: the interrupt
    # itself, never an RtidError ("stopped before any evaluation").
    def ctrl_c(*counts):
        raise KeyboardInterrupt

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            fit = rtid.identify(root / EMPS, rtid.params(path=root / AXIS), progress=ctrl_c)
    except KeyboardInterrupt:
        return
    assert fit.interrupted
