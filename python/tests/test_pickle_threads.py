"""Pickling, repr, threads (the GIL released), the progress callback and Ctrl-C."""
import _thread
import pickle
import threading

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES, updated


def test_pickle_round_trips():
    res = flexkin.run_scenario(EXAMPLES / "fig12_spatial_curve.json")
    again = pickle.loads(pickle.dumps(res))
    assert type(again) is flexkin.Result
    for key in ("frames", "steps", "link_angles", "lengths"):
        assert np.array_equal(getattr(again, key), getattr(res, key))
    assert repr(again) == repr(res) and again.full_report() == res.full_report()
    assert repr(again.metrics) == repr(res.metrics)
    options = flexkin.RunOptions(method="overall", substeps=3, overall={"rotation": 0.5})
    assert repr(pickle.loads(pickle.dumps(options))) == repr(options)
    weights = flexkin.ObjectiveWeights(squared=1, rotation=0.25)
    assert pickle.loads(pickle.dumps(weights)) == weights
    chain = flexkin.Chain(flexkin.arc(links=5), link_length=0.1)
    back = pickle.loads(pickle.dumps(chain))
    assert np.array_equal(back.points, chain.points) and np.array_equal(back.lengths, chain.lengths)
    scenario = flexkin.load_scenario(EXAMPLES / "fig10_planar_curve.json")
    assert repr(pickle.loads(pickle.dumps(scenario))) == repr(scenario)
    traj = flexkin.run_robot(EXAMPLES / "robot_planar_8link.json")
    back = pickle.loads(pickle.dumps(traj))
    assert np.array_equal(back.angles, traj.angles) and repr(back) == repr(traj)
    for obj in (res.accuracy, res.overall, options.overall, traj, chain, scenario):
        assert type(obj).__name__ in repr(obj)


def test_scenario_object_runs_as_its_file():
    path = EXAMPLES / "fig06_parabola_multi_step.json"
    scenario = flexkin.load_scenario(path)
    assert np.array_equal(flexkin.run_scenario(scenario).frames, flexkin.run_scenario(path).frames)
    assert scenario.options.method == "tractrix" and scenario.chain.num_links == 20


def big_run(seed):
    rng = np.random.default_rng(seed)
    points = np.cumsum(rng.uniform(0.1, 1.0, size=(2001, 2)), axis=0)
    path = points[0] + np.cumsum(rng.normal(size=(400, 2)), axis=0)
    return flexkin.run(points, path, substeps=4, record_every=50)


def test_threads_give_the_serial_results():
    serial = [big_run(seed) for seed in range(4)]
    results = [None] * 4

    def work(i):
        results[i] = big_run(i)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(serial, results):
        assert np.array_equal(a.frames, b.frames)
        assert a.metrics.l2_total == b.metrics.l2_total


def long_run(**kwargs):
    points = np.column_stack([np.arange(100001.0), np.zeros(100001)])
    steps = flexkin.split_pull(points[0], [-1e4, 1.0], 100000)
    return flexkin.run(points, steps, record_every=100000, link_angles=False, **kwargs)


def test_progress_callback_and_its_exception_stop_the_run():
    calls = []

    def progress(done, total):
        calls.append((done, total))
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        long_run(progress=progress)
    assert calls and calls[0][1] == 100000


def test_ctrl_c_stops_a_run():
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            long_run()
    finally:
        timer.cancel()


def test_progress_true_uses_tqdm_when_installed(fake_tqdm):
    res = flexkin.run(flexkin.parabola(links=5), [[0.1, 0.1], [0.2, 0.2]], progress=True)
    assert res.frames.shape == (3, 6, 2)
    assert fake_tqdm[0] == ("total", 2) and fake_tqdm[-1] == ("close",)
    assert updated(fake_tqdm) == 2


def test_the_gil_is_released_during_a_run():
    stop = threading.Event()
    outcome = []

    def progress(done, total):
        if stop.is_set():
            raise RuntimeError("stopped")

    def work():
        try:
            long_run(progress=progress)
        except RuntimeError as e:
            outcome.append(str(e))

    thread = threading.Thread(target=work)
    thread.start()
    count = 0
    import time
    end = time.monotonic() + 0.3
    while time.monotonic() < end:       # Python keeps running beside the run
        count += 1
    stop.set()
    thread.join()
    assert outcome == ["stopped"] and count > 10000


def test_scenario_options_changed_before_running():
    scenario = flexkin.load_scenario(EXAMPLES / "fig06_parabola_multi_step.json")
    scenario.options.substeps = 8
    scenario.options.record_every = 5
    res = flexkin.run_scenario(scenario)
    assert res.substeps == 8 and res.steps.tolist() == [0, 5]
