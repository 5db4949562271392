"""A sweep of 1,000 scenario variations on dask.distributed, checked against the serial run.

The variations are the paper's Sec. 5.1 chain (examples/fig06_parabola_multi_step.json: the
parabola y = x^2 in 20 links of 0.25) pulled in 10 directions by 5 distances, with 5 sub-step
counts and the 4 sequential link rules: 10 x 5 x 5 x 4 = 1,000 runs of `flexkin run`, each a
scenario dict given to flexkin.run_scenario on a worker. The results (flexkin.Result, which
pickles) come back to the client and are compared with the same runs made one after another in
this process: every array and number bit for bit (all but the run's clock, `seconds`).

By default the cluster is a LocalCluster of 2 worker processes on this machine; --scheduler
tcp://HOST:8786 runs the same code on a real cluster (docs/python-examples.md, "Sweeps on a
cluster"). Exits 1 if any result differs.

Usage: PYTHONPATH=build/python python3 examples/python/dask_sweep.py [--scheduler ADDRESS]
           [--workers N] [--count N] [--batch N]
"""
import argparse
import contextlib
import logging
import math
import sys
import time

import numpy as np

import flexkin

METHODS = ("tractrix", "ftl", "min_rotation", "min_joint_angle")
SUBSTEPS = (1, 2, 4, 8, 16)
DIRECTIONS = 10  # pull directions, evenly spaced around the circle
DISTANCES = (0.3, 0.6, 0.9, 1.2, 1.5)  # pull lengths (the chain is 5 long)


def variations(count=1000):
    """The first `count` of the 1,000 scenario dicts (JSON form, docs/scenario-format.md)."""
    out = []
    for method in METHODS:
        for substeps in SUBSTEPS:
            for k in range(DIRECTIONS):
                angle = 2.0 * math.pi * k / DIRECTIONS
                for distance in DISTANCES:
                    out.append({
                        "name": f"sweep_{len(out):04d}",
                        "curve": {"shape": "parabola", "a": 1, "links": 20, "link_length": 0.25},
                        "leader": {"pull": [distance * math.cos(angle), distance * math.sin(angle)],
                                   "steps": 10, "substeps": substeps},
                        "method": method,
                    })
    return out[:count]


def run_variation(scenario):
    """One variation: what runs on a worker (module level, so the task pickles)."""
    return flexkin.run_scenario(scenario)


def _bits(value):
    """A value as bytes with its type, shape and dtype: equal only if identical bit for bit."""
    if value is None or isinstance(value, (str, bool, int)):
        return repr(value).encode()
    array = np.asarray(value)
    return repr((array.dtype.str, array.shape)).encode() + array.tobytes()


def fingerprint(result):
    """Everything a run computes, for a bit-for-bit comparison (all but `seconds`, the clock)."""
    m, a, o = result.metrics, result.accuracy, result.overall
    fields = {
        "frames": result.frames, "steps": result.steps, "link_angles": result.link_angles,
        "lengths": result.lengths, "method": result.method, "substeps": result.substeps,
        "num_steps": result.num_steps, "scenario": result.scenario,
        "l2_per_step": m.l2_per_step, "l2_weighted_per_step": m.l2_weighted_per_step,
        "l2_total": m.l2_total, "l2_weighted_total": m.l2_weighted_total,
        "max_relative_length_error": m.max_relative_length_error, "path_length": m.path_length,
        "accuracy": [a.enabled, a.tolerance, a.max_substeps, a.substeps, a.order,
                     a.estimated_error, a.met],
        "weights": sorted(result.weights.as_dict().items()),
        "overall": [o.solves, o.failures, o.iterations, o.max_iterations,
                    o.constraint_violation, o.optimality, o.first_failure],
    }
    return {key: b"|".join(_bits(v) for v in value) if isinstance(value, list) else _bits(value)
            for key, value in fields.items()}


def differences(distributed, serial):
    """[(index, field), ...] where the two lists of results differ (empty: all identical)."""
    if len(distributed) != len(serial):
        return [(-1, f"{len(distributed)} results against {len(serial)}")]
    found = []
    for i, (d, s) in enumerate(zip(distributed, serial)):
        fd, fs = fingerprint(d), fingerprint(s)
        found.extend((i, key) for key in fs if fd[key] != fs[key])
    return found


def run_batch(scenarios):
    """Several variations in one task (for variations too small to pay a task's overhead)."""
    return [run_variation(s) for s in scenarios]


def run_distributed(client, scenarios, batch=1):
    """The variations on the cluster, `batch` to a task; the results in the order given."""
    if batch <= 1:
        return client.gather(client.map(run_variation, scenarios))
    batches = [scenarios[i:i + batch] for i in range(0, len(scenarios), batch)]
    return [r for part in client.gather(client.map(run_batch, batches)) for r in part]


def run_serial(scenarios):
    return [run_variation(s) for s in scenarios]


@contextlib.contextmanager
def cluster_client(scheduler=None, workers=2):
    """A Client of the cluster at `scheduler`, or of a LocalCluster of `workers` processes."""
    from dask.distributed import Client, LocalCluster
    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client:
        yield client


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scheduler", help="address of a running dask scheduler "
                        "(tcp://HOST:8786); default: a LocalCluster on this machine")
    parser.add_argument("--workers", type=int, default=2,
                        help="worker processes of the LocalCluster (default 2)")
    parser.add_argument("--count", type=int, default=1000, help="variations (default 1000)")
    parser.add_argument("--batch", type=int, default=1,
                        help="variations per task (default 1: each variation a task)")
    args = parser.parse_args(argv)
    if not 1 <= args.count <= 1000 or args.batch < 1 or args.workers < 1:
        parser.error("--count is 1 to 1000; --batch and --workers at least 1")
    scenarios = variations(args.count)

    start = time.perf_counter()
    with cluster_client(args.scheduler, args.workers) as client:
        where = args.scheduler or f"LocalCluster of {args.workers} worker processes"
        where += f", {args.batch} variation{'s' if args.batch > 1 else ''} per task"
        started = time.perf_counter()
        distributed = run_distributed(client, scenarios, args.batch)
        ran = time.perf_counter()
    closed = time.perf_counter()
    serial = run_serial(scenarios)
    done = time.perf_counter()

    print(f"{len(scenarios)} variations ({len(METHODS)} link rules x {len(SUBSTEPS)} sub-step "
          f"counts x {DIRECTIONS} directions x {len(DISTANCES)} distances), 20-link parabola")
    overhead = "connecting" if args.scheduler else "the cluster's start and close"
    print(f"dask.distributed ({where}): {ran - started:.3f} s for the sweep, "
          f"{closed - start:.3f} s with {overhead}")
    print(f"serial (this process): {done - closed:.3f} s")
    frames = sum(r.frames.shape[0] for r in serial)
    l2 = sum(r.metrics.l2_total for r in serial)
    print(f"{frames} frames, sum of the L2 metrics {l2:.9f}")
    found = differences(distributed, serial)
    if found:
        print(f"MISMATCH: {len(found)} differences, the first: variation {found[0][0]}, "
              f"{found[0][1]}")
        return 1
    print("identical: every result of the cluster equals the serial one bit for bit")
    return 0


if __name__ == "__main__":
    sys.exit(main())
