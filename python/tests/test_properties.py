"""Properties of the motion over random chains, 2D and 3D, through the Python module."""
import numpy as np
import pytest

import flexkin


def random_chain(rng, links, dim):
    """A random walk of links of random lengths in [0.5, 1.5]."""
    directions = rng.normal(size=(links, dim))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    lengths = rng.uniform(0.5, 1.5, size=links)
    return np.vstack([np.zeros(dim), np.cumsum(directions * lengths[:, None], axis=0)])


CASES = [(seed, dim, method) for seed in range(4) for dim in (2, 3) for method in ("tractrix", "ftl")]


@pytest.mark.parametrize("seed, dim, method", CASES)
def test_lengths_kept_and_trailing_end_never_faster(seed, dim, method):
    rng = np.random.default_rng(seed)
    points = random_chain(rng, links=int(rng.integers(1, 40)), dim=dim)
    chain = flexkin.Chain(points)
    path = points[0] + np.cumsum(rng.normal(scale=0.3, size=(60, dim)), axis=0)
    res = flexkin.run(chain, path, method=method)
    assert res.metrics.max_relative_length_error <= 1e-12
    links = np.linalg.norm(np.diff(res.frames, axis=1), axis=2)
    assert np.max(np.abs(links / chain.lengths - 1)) <= 1e-12
    # One sub-step per leader step: every point moves no farther than the point ahead of it.
    moves = np.linalg.norm(np.diff(res.frames, axis=0), axis=2)
    assert np.all(moves[:, 1:] <= moves[:, :-1] * (1 + 1e-12) + 1e-12)
    assert np.all(np.diff(res.metrics.path_length) <= 1e-12)


@pytest.mark.parametrize("seed, dim", [(s, d) for s in range(3) for d in (2, 3)])
def test_straight_pull_motion_dies_out_and_chain_aligns(seed, dim):
    rng = np.random.default_rng(100 + seed)
    points = random_chain(rng, links=15, dim=dim)
    chain = flexkin.Chain(points)
    direction = rng.normal(size=dim)
    direction /= np.linalg.norm(direction)
    total = chain.lengths.sum()
    # A short pull: the path length decreases along the chain, the motion dies out.
    short = flexkin.run(chain, flexkin.split_pull(points[0], 0.5 * direction, 20), substeps=4)
    profile = short.metrics.path_length
    assert profile[0] == pytest.approx(0.5, rel=1e-12)
    assert np.all(np.diff(profile) <= 1e-12) and profile[-1] < profile[0]
    # A long pull aligns every link with it.
    long = flexkin.run(chain, flexkin.split_pull(points[0], 20 * total * direction, 2000),
                       substeps=4, record_every=2000)
    assert np.max(long.link_angles[-1]) < 1e-3
    assert long.metrics.max_relative_length_error <= 1e-12


def test_chain_move_leader_in_place_matches_function():
    points = flexkin.helix(links=10, link_length=1.0)
    chain = flexkin.Chain(points, link_length=1.0)
    moved = flexkin.move_leader(chain, [1.0, 0.5, 0.2], substeps=8)
    chain.move_leader([1.0, 0.5, 0.2], substeps=8)
    assert np.array_equal(chain.points, moved)
    assert chain.max_relative_length_error() <= 1e-12
    for method in ("ftl", "min_rotation", "min_joint_angle"):
        out = flexkin.move_leader(flexkin.Chain(flexkin.arc(links=6), link_length=0.1),
                                  [0.9, 0.3], method=method)
        assert out.shape == (7, 2)


def test_link_steps_and_overall_step():
    tail = flexkin.tractrix_step([0, 0], [-1, 0], [1, 0], 1.0)
    assert tail.shape == (2,)
    assert np.linalg.norm(tail - [-1, 0]) == pytest.approx(1.0, rel=1e-14)
    ftl = flexkin.follow_the_leader_step([0, 0, 0], [0, 1, 0], [1, 0, 0], 1.0)
    assert np.linalg.norm(ftl - [0, 1, 0]) == pytest.approx(1.0, rel=1e-14)
    pts = flexkin.parabola(links=20)
    new, report = flexkin.overall_step(flexkin.Chain(pts, link_length=0.25), [0.1, 0.1],
                                       options={"l2": 1})
    assert report.converged and report.moving_points < 20
    assert np.array_equal(new[report.moving_points + 1:], pts[report.moving_points + 1:])
    res = flexkin.run(pts, [[0.1, 0.1]], method="overall", overall=flexkin.ObjectiveWeights(l2=1))
    assert res.overall.solves >= 1 and res.overall.failures == 0
    assert res.weights.l2 == 1 and res.weights.squared == 0


METHODS = ("tractrix", "ftl", "min_rotation", "min_joint_angle", "overall")


def joint_cosines(points):
    """The cosine of the angle between each link and the next."""
    links = np.diff(points, axis=0)
    links /= np.linalg.norm(links, axis=1, keepdims=True)
    return np.sum(links[:-1] * links[1:], axis=1)


@pytest.mark.parametrize("seed, dim, method",
                         [(s, d, m) for s in range(3) for d in (2, 3) for m in METHODS])
def test_every_method_keeps_the_lengths_and_its_own_property(seed, dim, method):
    """Each method's defining property, on random chains and random paths, step by step."""
    rng = np.random.default_rng(200 + seed)
    points = random_chain(rng, links=int(rng.integers(3, 25)), dim=dim)
    chain = flexkin.Chain(points)
    path = points[0] + np.cumsum(rng.normal(scale=0.2, size=(12, dim)), axis=0)
    res = flexkin.run(chain, path, method=method)
    frames = res.frames
    assert np.all(np.isfinite(frames))
    # Every method: the leading end on its path, every length kept.
    assert np.array_equal(frames[1:, 0], path)
    links = np.linalg.norm(np.diff(frames, axis=1), axis=2)
    assert np.max(np.abs(links / chain.lengths - 1)) <= 1e-12
    moves = np.linalg.norm(np.diff(frames, axis=0), axis=2)
    if method in ("tractrix", "ftl"):
        # No point moves farther than the point ahead of it.
        assert np.all(moves[:, 1:] <= moves[:, :-1] * (1 + 1e-12) + 1e-12)
    elif method == "min_rotation":
        # No link turns: the whole chain translates with its leading end.
        shift = frames - frames[:, :1]
        assert np.max(np.abs(shift - shift[0])) <= 1e-12 * (1 + np.abs(frames).max())
    elif method == "min_joint_angle":
        # Every joint angle kept: the chain behind the first link moves rigidly with it.
        for frame in frames[1:]:
            assert np.max(np.abs(joint_cosines(frame) - joint_cosines(points))) <= 1e-12
    else:
        # The overall step moves the chain no more (sum of squared moves, its objective) than the
        # tractrix step from the same configuration, which is feasible: it is the minimizer.
        for before, after, head in zip(frames[:-1], frames[1:], path):
            tractrix = flexkin.move_leader(flexkin.Chain(before, lengths=chain.lengths), head)
            assert np.sum((after - before) ** 2) <= np.sum((tractrix - before) ** 2) * (1 + 1e-12)
        assert res.overall.failures == 0
