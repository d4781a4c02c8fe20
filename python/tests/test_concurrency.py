"""Jobs run with the GIL released: two threads render at once, Python threads keep running while
a job does, and Ctrl-C (SIGINT's KeyboardInterrupt) stops a running job between its units of
work."""
import os
import signal
import threading
import time

import numpy as np
import pytest

import seamcl

A = dict(scene="quad2", size=(64, 48), method="traverse", msaa=4)
B = dict(scene="closeup-corner", size=(56, 40), method="discard", msaa=2)


def test_two_threads_render_at_once_and_get_what_each_renders_alone():
    alone = {name: seamcl.render(**kw).image for name, kw in (("a", A), ("b", B))}
    got, errors = {}, []
    start = threading.Barrier(2)

    def work(name, kw):
        try:
            start.wait()
            for _ in range(3):
                got.setdefault(name, []).append(seamcl.render(**kw).image)
        except BaseException as e:  # reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=("a", A)), threading.Thread(target=work, args=("b", B))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    for name in ("a", "b"):
        assert len(got[name]) == 3
        for image in got[name]:
            np.testing.assert_array_equal(image, alone[name])


def test_python_threads_run_while_a_job_renders():
    """A thread that only counts in Python records when it ran; while the main thread is inside a
    job of about a second, its longest pause is a small part of the job, which it could not be if
    the job held the GIL."""
    stamps, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.001)

    seamcl.render(scene="paper", size=(96, 108), repeat=1)  # kernels built, scene generator warm
    spinner = threading.Thread(target=tick)
    spinner.start()
    begin = time.perf_counter()
    # Mostly rendering, not the scene's bake: about 0.9 s on 2 idle cores (2026-12-04).
    seamcl.render(scene="paper", size=(480, 540), method="traverse", repeat=24)
    end = time.perf_counter()
    stop.set()
    spinner.join()
    inside = [t for t in stamps if begin <= t <= end]
    assert end - begin > 0.3, "the job is too short to tell"
    gaps = np.diff([begin, *inside, end])
    assert gaps.max() < 0.5 * (end - begin), f"longest pause {gaps.max():.3f} s of a {end - begin:.3f} s job"


def test_ctrl_c_stops_a_running_compare():
    lines = []
    timer = threading.Timer(0.3, os.kill, args=(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            seamcl.compare(scene="quad2", size=(64, 64), methods=["discard", "traverse"], msaa=[1, 2, 4, 8, 16],
                           repeat=200, no_cache=True, progress=lines.append)
    finally:
        timer.cancel()
    entries = [line for line in lines if line.startswith("entry ")]
    assert len(entries) < 10, "the compare ran to its end"
    # The process goes on: the next job runs.
    assert seamcl.render(scene="quad2", size=(8, 8)).image.shape == (8, 8, 4)


def test_an_exception_in_the_progress_callback_stops_the_job_and_is_raised():
    calls = []

    def progress(line):
        calls.append(line)
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        seamcl.render(scene="quad2", size=(8, 8), repeat=5, progress=progress)
    assert calls == ["render 1/5"]
