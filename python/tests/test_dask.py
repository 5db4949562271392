"""1,000 scenario variations on a dask.distributed LocalCluster give exactly the serial results
(examples/python/dask_sweep.py; docs/python-examples.md, "Sweeps on a cluster")."""
import importlib.util
import os
import pickle
import sys
import time

import numpy as np
import pytest

from conftest import SOURCE_DIR

distributed = pytest.importorskip("distributed")
psutil = pytest.importorskip("psutil")

SCRIPTS = SOURCE_DIR / "examples" / "python"
# tornado, under distributed 2022.12 with Python 3.11
pytestmark = pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")


def load_sweep():
    """The example imported as the module dask_sweep: its task function then pickles by name,
    as a function of one's own module does, and the workers import it (sys.path below)."""
    spec = importlib.util.spec_from_file_location("dask_sweep", SCRIPTS / "dask_sweep.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["dask_sweep"] = module
    spec.loader.exec_module(module)
    return module


sweep = load_sweep()


@pytest.fixture(scope="module")
def serial():
    return sweep.run_serial(sweep.variations())


def test_the_variations_are_1000_different_scenarios():
    scenarios = sweep.variations()
    assert len(scenarios) == 1000
    keys = {(s["method"], s["leader"]["substeps"], tuple(s["leader"]["pull"])) for s in scenarios}
    assert len(keys) == 1000


def test_the_comparison_sees_any_difference(serial):
    assert sweep.differences(serial, serial) == []
    again = pickle.loads(pickle.dumps(serial[:50]))   # as results come back from a worker
    assert sweep.differences(again, serial[:50]) == []
    shifted = serial[1:51]
    found = sweep.differences(shifted, serial[:50])
    assert {i for i, _ in found} == set(range(50))
    assert ("frames" in {key for _, key in found}) and ("l2_total" in {key for _, key in found})
    # one sub-step more: a difference in the last bits only is a difference
    close = sweep.variations(1)[0]
    close["leader"]["substeps"] = 3
    other = sweep.run_variation(close)
    assert np.abs(other.frames - serial[0].frames).max() < 1e-2
    assert sweep.differences([other], serial[:1])
    assert sweep.differences(serial[:2], serial[:1])


def test_local_cluster_gives_the_serial_results_exactly(serial, monkeypatch):
    # The workers unpickle run_variation by its module's name, so they import the module: a
    # LocalCluster's worker processes (multiprocessing's spawn) start with the client's sys.path.
    monkeypatch.syspath_prepend(str(SCRIPTS))
    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    with sweep.cluster_client(workers=2) as client:
        pids = client.run(os.getpid)
        assert len(pids) == 2 and os.getpid() not in pids.values()
        start = time.perf_counter()
        results = sweep.run_distributed(client, sweep.variations())
        seconds = time.perf_counter() - start
    print(f"1,000 variations on a LocalCluster of 2 processes: {seconds:.2f} s")
    assert len(results) == 1000
    assert all(type(r).__name__ == "Result" for r in results)
    assert sweep.differences(results, serial) == []
    for got, want in zip(results, serial):   # and directly, not only through the example's check
        assert np.array_equal(got.frames, want.frames)
        assert np.array_equal(got.link_angles, want.link_angles)
        assert got.metrics.l2_total.hex() == want.metrics.l2_total.hex()
        assert np.array_equal(got.metrics.path_length, want.metrics.path_length)
    # The cluster's processes are gone once its context is left. multiprocessing's resource
    # tracker is not the cluster's: started with the first worker, it lives as long as this
    # process, by design.
    def left():
        return [p for p in me.children(recursive=True)
                if p.pid not in before and not is_resource_tracker(p)]

    deadline = time.monotonic() + 30  # generous: worker processes exit slowly on a loaded machine
    while left() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not left(), f"processes left behind: {left()}"


def is_resource_tracker(process):
    try:
        return any("resource_tracker" in part for part in process.cmdline())
    except psutil.Error:  # gone meanwhile
        return True
