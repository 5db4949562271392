"""flexkin.move_tree: trees driven at one point (docs/trees.md). A link's step depends only on how
its leading end moved, so a path driven at its first point moves as move_leader moves the chain,
and a branch as the chain from the driven point along it."""
import numpy as np
import pytest

import flexkin


def binary_tree(depth):
    count = 2 ** (depth + 1) - 1
    parents = [-1] + [(i - 1) // 2 for i in range(1, count)]
    points = np.zeros((count, 3))
    for i in range(1, count):
        level = int(np.log2(i + 1))
        side = (1.0 if i % 2 else -1.0) * 0.7 ** level
        step = np.array([side, 0.3, 0.1 * level])
        points[i] = points[parents[i]] + 0.5 * step / np.linalg.norm(step)
    return points, parents


def test_a_path_moves_as_move_leader_bit_for_bit():
    points = flexkin.parabola(a=1.0, links=12, link_length=0.25)
    path = [[0.3, 0.2], [0.5, 0.6], [0.1, 0.9]]
    frames = flexkin.move_tree(points, [-1] + list(range(12)), path, substeps=2)
    assert frames.shape == (4, 13, 2)
    chain = flexkin.Chain(points)  # its lengths kept, as the tree keeps its own
    for i, target in enumerate(path):
        chain.move_leader(target, substeps=2)
        np.testing.assert_array_equal(frames[i + 1], chain.points)


def test_each_branch_moves_as_the_chain_from_the_driven_point_along_it():
    points, parents = binary_tree(4)
    driven = 5  # interior: its parent 2, its children 11 and 12
    path = [points[driven] + [0.4, -0.2, 0.1], points[driven] + [0.9, 0.3, -0.2]]
    frames = flexkin.move_tree(points, parents, path, driven=driven, method="ftl")
    # The way from 5 up through the root and down the other side to leaf 20.
    branch = [5, 2, 0, 1, 4, 9, 20]
    chain = flexkin.Chain(points[branch])
    for i, target in enumerate(path):
        chain.move_leader(target, method="ftl")
        np.testing.assert_array_equal(frames[i + 1][branch], chain.points)
    lengths = np.linalg.norm(points[1:] - points[np.array(parents[1:])], axis=1)
    moved = np.linalg.norm(frames[-1][1:] - frames[-1][np.array(parents[1:])], axis=1)
    assert np.max(np.abs(moved - lengths) / lengths) < 1e-14


@pytest.mark.parametrize("parents, field, part", [
    ([-1, 0, 1], "parents", "3 entries for 4 points"),
    ([-1, 0, -1, 1], "parents[2]", "is the root already"),
    ([-1, 0, 7, 1], "parents[2]", "a point 0..3 other than 2"),
    ([-1, 0, 3, 2], "parents[2]", "the cycle 2 -> 3 -> 2"),
    ([-1, 0, 1.0, 2], "parents[2]", "is not an integer"),
    ([-1, 0, True, 2], "parents[2]", "is not an integer"),
])
def test_bad_parents_are_named(parents, field, part):
    points = [[0, 0], [1, 0], [2, 0], [3, 0]]
    with pytest.raises(flexkin.InputError) as e:
        flexkin.move_tree(points, parents, [[0.1, 0.1]])
    assert e.value.field == field and part in str(e.value)


def test_bad_arguments_are_named():
    points = [[0, 0], [1, 0], [1, 0], [3, 0]]
    with pytest.raises(flexkin.InputError) as e:
        flexkin.move_tree(points, [-1, 0, 1, 2], [[0.1, 0.1]])
    assert e.value.field == "points[2]" and "from its parent point 1" in str(e.value)
    points[2] = [2, 0]
    for kwargs, field in [({"driven": 4}, "driven"), ({"method": "overall"}, "method"),
                          ({"substeps": 0}, "substeps")]:
        with pytest.raises(flexkin.InputError) as e:
            flexkin.move_tree(points, [-1, 0, 1, 2], [[0.1, 0.1]], **kwargs)
        assert e.value.field == field
    with pytest.raises(flexkin.InputError) as e:
        flexkin.move_tree(points, [-1, 0, 1, 2], [[0.1, 0.1, 0.0]])
    assert e.value.field == "path"
