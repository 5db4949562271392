"""The strand engine from Python (docs/strands.md): each strand is move_leader of its own chain
(bit for bit on the scalar engine, to 1e-14 on the SIMD ones), lengths are kept, threads change
no bit, pinned points stay rigid with the body, bad input is refused naming the argument."""
import copy
import os
import pickle
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import flexkin


def make_strands(count=21, dim=3, links=(3, 5, 9, 12), seed=1):
    """Wavy strands of mixed link counts, rooted on a unit sphere (3D) or circle (2D)."""
    rng = np.random.default_rng(seed)
    strands = []
    for i in range(count):
        n = links[i % len(links)]
        direction = rng.normal(size=dim)
        direction /= np.linalg.norm(direction)
        steps = direction * 0.1 + rng.normal(scale=0.03, size=(n, dim))
        root = direction
        strands.append(np.vstack([root, root + np.cumsum(steps, axis=0)]))
    return strands


def poses(frames, dim=3):
    """A body that turns and travels: (rotation (3, 3), translation (3,)) per frame."""
    out = []
    for f in range(1, frames + 1):
        a = 0.05 * f
        if dim == 2:
            out.append(flexkin.BodyPose.planar(a, 0.02 * f, -0.01 * f))
        else:
            w, x, y, z = np.cos(a / 2), *(np.sin(a / 2) * np.array([0.3, 0.8, 0.52]) /
                                          np.linalg.norm([0.3, 0.8, 0.52]))
            out.append(flexkin.BodyPose.from_quaternion(w, x, y, z, [0.02 * f, 0.01 * f, 0.0]))
    return out


def relative_difference(a, b):
    return float(np.max(np.abs(a - b) / (1.0 + np.abs(a))))


def tolerance(batch):
    """What the C++ library promises: bit for bit on the scalar engine, 1e-14 on SIMD ones."""
    return 0.0 if batch.engine == "scalar" else 1e-14


@pytest.mark.parametrize("method", ["tractrix", "ftl"])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("substeps", [1, 3])
def test_each_strand_is_move_leader_of_its_chain(method, dim, substeps):
    strands = make_strands(dim=dim)
    batch = flexkin.StrandBatch(strands, method=method, substeps=substeps, threads=2)
    chains = [flexkin.Chain(s) for s in strands]
    worst = 0.0
    for pose in poses(20, dim):
        batch.step(pose)
        r, t = pose.rotation, pose.translation
        for i, chain in enumerate(chains):
            root = (r @ np.append(strands[i][0], [0.0] * (3 - dim)) + t)[:dim]
            chain.move_leader(root, method=method, substeps=substeps)
            got = batch.strand(i)
            assert got.shape == chain.points.shape
            worst = max(worst, relative_difference(got, chain.points))
    assert worst <= tolerance(batch), (batch.engine, worst)


def test_root_points_move_every_strand_as_move_leader():
    strands = make_strands(count=9, links=(4, 7))
    batch = flexkin.StrandBatch(strands)
    chains = [flexkin.Chain(s) for s in strands]
    rng = np.random.default_rng(3)
    for _ in range(10):
        roots = np.array([c.points[0] for c in chains]) + rng.normal(scale=0.05, size=(9, 3))
        batch.step(roots=roots)
        for i, chain in enumerate(chains):
            chain.move_leader(roots[i])
            assert relative_difference(batch.strand(i), chain.points) <= tolerance(batch)
            assert batch.strand(i)[0].tobytes() == roots[i].tobytes()


SCALAR_CHECK = textwrap.dedent("""
    import numpy as np, flexkin, sys
    sys.path.insert(0, sys.argv[1])
    from test_strands import make_strands, poses
    for method in ("tractrix", "ftl"):
        strands = make_strands()
        batch = flexkin.StrandBatch(strands, method=method, threads=2)
        assert batch.engine == "scalar", batch.engine
        chains = [flexkin.Chain(s) for s in strands]
        for pose in poses(15):
            batch.step(pose)
            for i, chain in enumerate(chains):
                chain.move_leader(pose.rotation @ strands[i][0] + pose.translation,
                                  method=method)
                assert batch.strand(i).tobytes() == chain.points.tobytes(), (method, i)
    print("bit for bit")
""")


def test_the_scalar_engine_is_move_leader_bit_for_bit():
    env = dict(os.environ, FLEXKIN_SIMD="scalar")
    done = subprocess.run([sys.executable, "-c", SCALAR_CHECK, os.path.dirname(__file__)],
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "bit for bit" in done.stdout


def test_lengths_are_kept_over_many_frames():
    strands = make_strands(count=40, links=(6, 16))
    for method in ("tractrix", "ftl"):
        batch = flexkin.StrandBatch(strands, method=method)
        for pose in poses(300):
            batch.step(pose)
        for i, s in enumerate(strands):
            lengths = np.linalg.norm(np.diff(s, axis=0), axis=1)
            now = np.linalg.norm(np.diff(batch.strand(i), axis=0), axis=1)
            assert np.max(np.abs(now - lengths) / lengths) < 1e-12, (method, i)


def test_threads_change_no_bit():
    strands = make_strands(count=70, links=(3, 8, 20))
    results = []
    for threads in (1, 2, 3):
        batch = flexkin.StrandBatch(strands, threads=threads, pinned=2, substeps=2)
        assert batch.options.threads == threads
        for pose in poses(12):
            batch.step(pose)
        results.append(b"".join(p.tobytes() for p in batch.points()))
    assert results[0] == results[1] == results[2]


def test_pinned_points_are_rigid_with_the_body():
    strands = make_strands(count=12, links=(2, 5, 9))
    rest = flexkin.BodyPose.from_quaternion(0.8, 0.2, 0.1, -0.3, [0.5, -0.2, 0.1])
    batch = flexkin.StrandBatch(strands, pinned=3, rest=rest)
    # the strands' points in body coordinates of the rest pose
    body = [(s - rest.translation) @ rest.rotation for s in strands]
    for pose in poses(15):
        batch.step(pose)
        for i in range(len(strands)):
            got = batch.strand(i)
            k = min(3, len(got))
            expected = body[i][:k] @ pose.rotation.T + pose.translation
            assert np.max(np.abs(got[:k] - expected)) < 1e-14
            if len(got) <= 3:         # a strand of no more than `pinned` points is rigid
                assert np.max(np.abs(got - body[i] @ pose.rotation.T - pose.translation)) < 1e-14


def test_pose_forms_agree():
    strands = make_strands(count=5)
    pose = poses(3)[-1]
    forms = [pose, pose.matrix(), (pose.rotation, pose.translation),
             {"rotation": pose.rotation, "translation": pose.translation},
             flexkin.BodyPose.from_matrix(pose.matrix())]
    results = []
    for form in forms:
        batch = flexkin.StrandBatch(strands)
        batch.step(form)
        results.append(b"".join(p.tobytes() for p in batch.points()))
    assert all(r == results[0] for r in results)
    q = flexkin.BodyPose.from_quaternion(0.5, 0.5, 0.5, 0.5, [1, 2])
    assert flexkin.BodyPose([0.5, 0.5, 0.5, 0.5], [1, 2, 0]) == q
    assert q.translation.tolist() == [1.0, 2.0, 0.0]
    assert flexkin.BodyPose() == flexkin.BodyPose(np.eye(3), [0, 0, 0])


def test_a_body_at_rest_moves_nothing():
    strands = make_strands(count=6)
    rest = flexkin.BodyPose.planar(0.3, 1.0, 2.0)
    batch = flexkin.StrandBatch(strands, rest=rest, pinned=2)
    before = batch.points()
    batch.step(rest)
    for a, b in zip(before, batch.points()):
        assert np.max(np.abs(a - b)) < 1e-14


def test_batch_accessors():
    strands = make_strands(count=5, links=(2, 4))
    batch = flexkin.StrandBatch(strands, method="ftl", substeps=2, pinned=2)
    assert len(batch) == 5 and batch.dim == 3
    assert [batch.num_links(i) for i in range(5)] == [2, 4, 2, 4, 2]
    assert batch.num_links(-1) == 2
    assert batch.engine in ("scalar", "avx2", "avx512")
    assert batch.options == flexkin.StrandOptions(method="ftl", substeps=2, pinned=2)
    assert batch.rest == flexkin.BodyPose()
    for i, s in enumerate(strands):
        assert batch.strand(i).tobytes() == np.asarray(s, dtype=np.float64).tobytes()
    assert batch.strand(-1).tobytes() == batch.strand(4).tobytes()
    assert "5 strands" in repr(batch) and "2 to 4 links" in repr(batch)
    equal = flexkin.StrandBatch([flexkin.line(links=3), flexkin.line(start=[0, 1], links=3)])
    assert equal.as_array().shape == (2, 4, 2)
    empty = flexkin.StrandBatch([])
    assert len(empty) == 0 and empty.points() == []
    options = flexkin.StrandBatch(strands, options={"method": "ftl", "pinned": 2}).options
    assert options == flexkin.StrandOptions(method="ftl", pinned=2)


def test_run_strands_is_the_batch_stepped_frame_by_frame():
    strands = make_strands(count=8, links=(6,))
    sequence = poses(7)
    matrices = np.array([p.matrix() for p in sequence])
    frames = flexkin.run_strands(strands, matrices, method="ftl", record_every=3, threads=2)
    batch = flexkin.StrandBatch(strands, method="ftl")
    expected = [batch.as_array()]
    for f, pose in enumerate(sequence, start=1):
        batch.step(pose)
        if f % 3 == 0 or f == len(sequence):
            expected.append(batch.as_array())
    assert frames.shape == (4, 8, 7, 3)
    assert frames.tobytes() == np.array(expected).tobytes()
    split = flexkin.run_strands(strands, matrices[:, :3, :3], translations=matrices[:, :3, 3],
                                method="ftl", record_every=3)
    assert split.tobytes() == frames.tobytes()


def refused(field, call, *args, **kwargs):
    with pytest.raises(flexkin.InputError) as error:
        call(*args, **kwargs)
    assert error.value.field == field, (error.value.field, str(error.value))
    return error.value


def test_bad_input_is_refused_naming_the_argument():
    good = make_strands(count=3, links=(3,))
    bad = [s.copy() for s in good]
    bad[1][2, 0] = np.nan
    refused("strands[1][2][0]", flexkin.StrandBatch, bad)
    refused("strands[2]", flexkin.StrandBatch, good[:2] + [[[0.0, 0.0, 0.0]]])
    refused("strands[1]", flexkin.StrandBatch, [good[0], good[1][:, :2]])
    refused("strands[0]", flexkin.StrandBatch, [[[0, 0], [0, 0]]])     # a link of length 0
    refused("strands", flexkin.StrandBatch, 5)
    refused("method", flexkin.StrandBatch, good, method="overall")
    refused("method", flexkin.StrandBatch, good, method="bogus")
    refused("substeps", flexkin.StrandBatch, good, substeps=0)
    refused("pinned", flexkin.StrandBatch, good, pinned=0)
    refused("threads", flexkin.StrandBatch, good, threads=-1)
    refused("rest.rotation", flexkin.StrandBatch, good, rest=(np.ones((3, 3)), [0, 0, 0]))
    refused("options.pinned", flexkin.StrandBatch, good, options={"pinned": 0})
    batch = flexkin.StrandBatch(good)
    refused("roots", batch.step, roots=np.zeros((2, 3)))
    refused("roots", batch.step, roots=np.zeros((3, 2)))
    refused("roots[1][2]", batch.step, roots=[[0, 0, 0], [0, 0, np.inf], [0, 0, 0]])
    refused("roots", batch.step, flexkin.BodyPose(), roots=np.zeros((3, 3)))
    refused("pose", batch.step)
    refused("pose.rotation", batch.step, (np.diag([1.0, 1.0, -1.0]), [0, 0, 0]))
    refused("pose.rotation", batch.step, flexkin.BodyPose(2 * np.eye(3)))
    refused("pose.translation[1]", batch.step, (np.eye(3), [0, np.nan, 0]))
    refused("pose.rotation", batch.step, (np.eye(2), [0, 0, 0]))
    refused("pose.rotation", batch.step, ([0, 0, 0, 0], [0, 0, 0]))
    refused("pose", batch.step, np.eye(3))
    refused("pose", batch.step, "identity")
    refused("pose.scale", batch.step, {"scale": 2})
    refused("i", batch.strand, 3)
    refused("i", batch.num_links, -4)
    mixed = flexkin.StrandBatch(make_strands(count=2, links=(2, 3)))
    refused("strands", mixed.as_array)
    refused("strands", flexkin.run_strands, make_strands(count=2, links=(2, 3)), [np.eye(4)])
    refused("poses", flexkin.run_strands, good, np.zeros((2, 3, 4)))
    turn = np.eye(4)
    turn[0, 0] = -1.0
    refused("poses[1].rotation", flexkin.run_strands, good, [np.eye(4), turn])
    refused("record_every", flexkin.run_strands, good, [np.eye(4)], record_every=0)
    refused("quaternion", flexkin.BodyPose.from_quaternion, 0, 0, 0, 0)
    refused("translation", flexkin.BodyPose.from_quaternion, 1, 0, 0, 0, [1, 2, 3, 4])
    refused("matrix", flexkin.BodyPose.from_matrix, np.ones((4, 4)))
    # the batch is unchanged by a refused step
    assert batch.as_array().tobytes() == np.array(good).tobytes()


def test_options_and_poses_pickle_and_compare():
    options = flexkin.StrandOptions(method="ftl", substeps=4, pinned=2, threads=0)
    pose = flexkin.BodyPose.from_quaternion(0.9, 0.1, -0.3, 0.2, [1.0, 2.0, 3.0])
    for obj in (options, pose):
        for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
            back = pickle.loads(pickle.dumps(obj, protocol=protocol))
            assert back == obj and type(back) is type(obj)
        assert copy.deepcopy(obj) == obj
    assert repr(options) == "StrandOptions(method='ftl', substeps=4, pinned=2, threads=0)"
    assert options != flexkin.StrandOptions()
    changed = copy.copy(options)
    changed.method = "tractrix"
    assert changed != options and changed.method == "tractrix"
    refused("method", setattr, changed, "method", "nope")
    changed.substeps = 0
    refused("substeps", changed.validate)
    assert pickle.loads(pickle.dumps(pose)).rotation.tobytes() == pose.rotation.tobytes()


def test_help_describes_the_strand_api():
    for obj in (flexkin.StrandBatch, flexkin.StrandOptions, flexkin.BodyPose,
                flexkin.run_strands, flexkin.StrandBatch.step, flexkin.StrandBatch.as_array,
                flexkin.BodyPose.from_quaternion, flexkin.BodyPose.planar):
        assert obj.__doc__ and len(obj.__doc__.strip()) > 40, obj
    assert "GIL" in flexkin.StrandBatch.step.__doc__
    assert "(S, n+1, dim)" in flexkin.StrandBatch.as_array.__doc__
    assert "(F, 4, 4)" in flexkin.run_strands.__doc__


def test_python_threads_may_step_batches_at_once():
    import concurrent.futures
    strands = make_strands(count=30, links=(10,))
    sequence = poses(20)

    def run(_):
        batch = flexkin.StrandBatch(strands)
        for pose in sequence:
            batch.step(pose)
        return batch.as_array().tobytes()

    alone = run(0)
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        assert all(r == alone for r in pool.map(run, range(8)))
    shared = flexkin.StrandBatch(strands)        # one batch shared: steps do not interleave
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        list(pool.map(lambda k: shared.step(roots=shared.as_array()[:, 0]), range(16)))
    assert shared.as_array().tobytes() == np.array(strands).tobytes()
