"""The GIL is released while a session advances (another Python thread runs meanwhile), a
session refuses a second thread's call while it is busy, and Ctrl-C (SIGINT) stops a long
advance between two events with the session usable at the time reached."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import kinetic

N = 4000
END = 20.0


@pytest.fixture(autouse=True)
def sigint_raises_keyboard_interrupt():
    """Python's own Ctrl-C handler, whatever the process inherited: a shell that starts the
    suite in the background without job control ignores SIGINT, and Python then keeps ignoring
    it."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def long_sort(seed=1):
    rng = np.random.default_rng(seed)
    m = rng.uniform(-1, 1, size=(N, 1, 2))
    return kinetic.Sort(m), m


def test_gil_released_during_advance():
    s, _ = long_sort()
    s.sorted()  # build first: the build is not what is measured
    done = threading.Event()
    elapsed = []

    started = threading.Event()

    def work():
        start = time.perf_counter()
        started.set()
        s.advance(END)
        elapsed.append(time.perf_counter() - start)
        done.set()

    worker = threading.Thread(target=work)
    ticks = 0
    busy_refused = False
    worker.start()
    started.wait()
    while not done.is_set():
        ticks += 1
        if not busy_refused and ticks > 10:
            with pytest.raises(RuntimeError, match="busy with another call"):
                s.sorted()
            busy_refused = True
        time.sleep(0.001)
    worker.join()
    # The advance must have been long enough for the count to mean something, and this thread
    # ran all along (with the GIL held by the advance it would not have run at all).
    assert elapsed[0] > 0.1, "the workload is too small to tell"
    assert ticks >= 0.2 * elapsed[0] / 0.001, (ticks, elapsed)
    assert busy_refused
    assert s.now == END and s.validate()


def test_ctrl_c_interrupts_advance_and_the_session_stays_usable():
    s, m = long_sort(2)
    s.sorted()
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        s.advance(END)
    timer.join()
    assert s.now < END, "the advance finished before the signal: make the workload larger"
    assert s.now > 0.0 and s.counters()["events"]["processed"] > 0  # stopped on its way
    assert s.validate()
    s.advance(END)
    x = m[:, 0, 0] + END * m[:, 0, 1]
    order = s.sorted()
    assert np.all(np.diff(x[order]) >= -1e-9)


def test_a_handler_that_does_not_raise_lets_the_advance_finish():
    s, _ = long_sort(3)
    s.sorted()
    calls = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: calls.append(time.perf_counter()))
    try:
        timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        s.advance(END)
        returned = time.perf_counter()
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert s.now == END
    assert len(calls) == 1
    # The handler ran while the advance was stopped, not after it returned (as it would if the
    # advance ignored the signal and Python ran the handler later).
    assert returned - calls[0] > 0.1, (returned, calls)


def test_ctrl_c_in_a_loop_of_short_advances_is_not_lost():
    m = np.random.default_rng(5).uniform(-1, 1, size=(200, 1, 2))
    s = kinetic.Sort(m)
    timer = threading.Timer(0.1, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        while time.perf_counter() - start < 5.0:
            s.advance(s.now + 1e-7)
    timer.join()
    assert time.perf_counter() - start < 2.0
    assert s.validate()


def test_ctrl_c_with_the_default_handler_ends_the_process():
    """signal.SIG_DFL: Ctrl-C kills the process, as the user asked, even inside an advance."""
    import subprocess
    import sys
    code = (
        "import os, signal, threading, numpy as np, kinetic\n"
        "signal.signal(signal.SIGINT, signal.SIG_DFL)\n"
        "s = kinetic.Sort(np.random.default_rng(2).uniform(-1, 1, size=(%d, 1, 2)))\n"
        "s.sorted()\n"
        "threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT)).start()\n"
        "s.advance(%r)\n"
        "print('finished')\n" % (N, END))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == -signal.SIGINT, (done.returncode, done.stdout, done.stderr)
    assert "finished" not in done.stdout


def test_ctrl_c_stops_a_run():
    sc = kinetic.generate("randdc", n=2000, seed=4, queries=1)
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        kinetic.run(sc, "sort")
    timer.join()
    assert time.perf_counter() - start < 0.4  # the whole run takes about 0.5 s


def test_run_releases_the_gil():
    sc = kinetic.generate("randdc", n=2000, seed=4, queries=1)
    result = {}
    worker = threading.Thread(target=lambda: result.update(kinetic.run(sc, "sort")))
    ticks = 0
    worker.start()
    start = time.perf_counter()
    while worker.is_alive():
        ticks += 1
        time.sleep(0.001)
    elapsed = time.perf_counter() - start
    worker.join()
    assert result["outcome"] == "completed"
    assert elapsed > 0.1, "the workload is too small to tell"
    assert ticks >= 0.2 * elapsed / 0.001, (ticks, elapsed)
