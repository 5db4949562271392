"""flexkin.reach_tree: several targets and fixed points on a tree (docs/trees.md, "Several
targets"). The targets are reachable by construction (points of another configuration of the same
tree), so every frame must reach them; one target with nothing fixed moves as move_tree moves the
tree driven at that point, bit for bit; a target out of reach reports its residual."""
import pathlib
import re

import numpy as np
import pytest

import flexkin

# Two arms of three links on a shoulder (point 2), on a spine of two links from the base (point 0).
ARMS = np.array([[0, 0], [0, 1], [0, 2], [0.8, 2.3], [1.6, 2.0], [2.4, 2.2], [-0.8, 2.3],
                 [-1.6, 2.0], [-2.4, 2.2]])
ARM_PARENTS = [-1, 0, 1, 2, 3, 4, 2, 6, 7]


def lengths(points, parents):
    return np.array([np.linalg.norm(points[i] - points[p]) for i, p in enumerate(parents) if p >= 0])


def bent(points, parents, angle, seed):
    """The tree with every link turned by a random angle up to `angle`, its length kept."""
    rng = np.random.default_rng(seed)
    out = points.copy()
    for i, p in enumerate(parents):
        if p < 0:
            continue
        link = points[i] - points[p]
        a = rng.uniform(-angle, angle)
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        out[i] = out[p] + rot @ link
    return out


@pytest.mark.parametrize("method", ["tractrix", "ftl"])
@pytest.mark.parametrize("rule", ["centroid", "keep_links"])
def test_the_hands_reach_reachable_targets_in_every_frame(method, rule):
    goals = [bent(ARMS, ARM_PARENTS, 0.3, seed) for seed in range(5)]
    paths = np.array([[g[5], g[8]] for g in goals])
    frames, report = flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], paths, fixed=[0], method=method,
                                        branch_rule=rule)
    assert frames.shape == (6, 9, 2)
    assert report["reached"].all() and report["root"] == 0
    assert (report["residual"] <= 1e-10).all()
    start = lengths(ARMS, ARM_PARENTS)
    for f, goal in enumerate(goals):
        np.testing.assert_allclose(frames[f + 1][[5, 8]], goal[[5, 8]], rtol=0, atol=1e-10 * start.max())
        np.testing.assert_array_equal(frames[f + 1][0], ARMS[0])
        np.testing.assert_allclose(lengths(frames[f + 1], ARM_PARENTS), start, rtol=1e-14)


@pytest.mark.parametrize("driven", [0, 4, 8])
def test_one_target_and_nothing_fixed_moves_as_move_tree(driven):
    path = ARMS[driven] + np.array([[0.3, 0.1], [0.5, -0.2], [0.2, -0.6]])
    frames, report = flexkin.reach_tree(ARMS, ARM_PARENTS, [driven], path[:, None, :])
    expected = flexkin.move_tree(ARMS, ARM_PARENTS, path, driven=driven)
    np.testing.assert_array_equal(frames, expected)
    assert (report["passes"] == 1).all() and (report["residual"] == 0).all()


def test_a_target_out_of_reach_reports_its_residual():
    points = np.array([[float(i), 0.0] for i in range(6)])  # 5 unit links along x
    parents = [-1, 0, 1, 2, 3, 4]
    frames, report = flexkin.reach_tree(points, parents, [5], [[[0.0, 8.0]]], fixed=[0])
    assert not report["reached"][0]
    assert report["residual"][0] == pytest.approx(3.0, abs=1e-3)  # 8 away, 5 long
    assert np.linalg.norm(frames[1][5] - [0.0, 8.0]) == pytest.approx(report["residual"][0], abs=1e-15)


@pytest.mark.parametrize("kwargs, field, part", [
    (dict(targets=[5, 9]), "targets[1]", "0..8"),
    (dict(targets=[5, 5]), "targets[1]", "targets[0] drives"),
    (dict(fixed=[0, 5]), "fixed[1]", "targets[0] drives"),
    (dict(targets=[]), "targets", "at least one"),
    (dict(weights=[1.0]), "weights", "one per target"),
    (dict(weights=[1.0, -2.0]), "weights[1]", "> 0"),
    (dict(method="overall"), "method", "\"tractrix\" or \"ftl\""),
    (dict(branch_rule="mean"), "branch_rule", "\"centroid\" or \"keep_links\""),
    (dict(tolerance=0.0), "tolerance", "> 0"),
    (dict(max_passes=0), "max_passes", ">= 1"),
    (dict(paths=np.zeros((3, 1, 2))), "paths", "expected (m, 2, 2)"),
    (dict(paths=np.full((1, 2, 2), np.nan)), "paths[0][0]", "non-finite"),
])
def test_bad_arguments_are_named(kwargs, field, part):
    args = dict(targets=[5, 8], paths=np.zeros((1, 2, 2)) + [[2.0, 2.5], [-2.0, 2.5]], fixed=[0])
    args.update(kwargs)
    targets, paths = args.pop("targets"), args.pop("paths")
    with pytest.raises(flexkin.InputError) as error:
        flexkin.reach_tree(ARMS, ARM_PARENTS, targets, paths, **args)
    assert error.value.field == field
    assert part in str(error.value)


def test_overall_gives_the_least_motion_that_reaches_the_targets():
    paths = np.array([[ARMS[5] + [0.05, 0.03], ARMS[8] + [-0.04, 0.05]]])
    passes, _ = flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], paths, fixed=[0])
    frames, report = flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], paths, fixed=[0],
                                        overall={"squared": 1.0})
    assert report["converged"].all()
    np.testing.assert_array_equal(frames[1][[5, 8]], paths[0])
    np.testing.assert_array_equal(frames[1][0], ARMS[0])
    np.testing.assert_allclose(lengths(frames[1], ARM_PARENTS), lengths(ARMS, ARM_PARENTS), rtol=1e-14)
    free = [1, 2, 3, 4, 6, 7]
    moved = lambda f: float(np.sum((f[1][free] - ARMS[free]) ** 2))
    assert moved(frames) < moved(passes)


def test_overall_refuses_terms_trees_do_not_take():
    with pytest.raises(flexkin.InputError) as error:
        flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], np.array([[ARMS[5], ARMS[8]]]), fixed=[0],
                           overall={"l2": 1.0})
    assert error.value.field == "weights.l2"


def test_a_tree_scenario_runs_through_the_front_door(tmp_path):
    scenario = {
        "format": "flexkin-tree",
        "tree": {"points": ARMS.tolist(), "parents": ARM_PARENTS},
        "targets": [{"point": 5, "path": [(ARMS[5] + [0.05, 0.03]).tolist()]},
                    {"point": 8, "path": [(ARMS[8] + [-0.04, 0.05]).tolist()]}],
        "fixed": [0],
    }
    result = flexkin.run_scenario(scenario, output=tmp_path / "tree.npz")
    expected, report = flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8],
                                          [[ARMS[5] + [0.05, 0.03], ARMS[8] + [-0.04, 0.05]]],
                                          fixed=[0])
    np.testing.assert_array_equal(result["frames"], expected)
    np.testing.assert_array_equal(result["passes"], report["passes"])
    with np.load(tmp_path / "tree.npz") as archive:
        np.testing.assert_array_equal(archive["frames"], expected)
        np.testing.assert_array_equal(archive["parents"], ARM_PARENTS)
    scenario["fixed"] = [0, 5]
    with pytest.raises(flexkin.InputError) as error:
        flexkin.run_scenario(scenario)
    assert error.value.field == "/fixed/1"


def test_a_tree_result_is_drawn_by_render(tmp_path):
    scenario = {
        "format": "flexkin-tree",
        "tree": {"points": ARMS.tolist(), "parents": ARM_PARENTS},
        "targets": [{"point": 5, "path": [(ARMS[5] + [0.05 * k, 0.03 * k]).tolist()
                                          for k in range(1, 6)]},
                    {"point": 8, "path": [(ARMS[8] + [-0.04 * k, 0.05 * k]).tolist()
                                          for k in range(1, 6)]}],
        "fixed": [0],
    }
    result = flexkin.run_scenario(scenario, output=tmp_path / "tree.npz")
    written = flexkin.render(tmp_path / "tree.npz", tmp_path / "drawn", "png,glb")
    assert [pathlib.Path(p).name for p in written] == ["tree.png", "tree.glb"]
    times, positions = flexkin.gltf_joint_positions(tmp_path / "drawn" / "tree.glb")
    assert len(times) == len(result["frames"])
    # Joint 0 sits on the root, point 0 (the fixed base).
    np.testing.assert_allclose(positions[:, 0, :], result["frames"][:, 0, :], atol=1e-6)
    # Plots of a tree: the points' path lengths, the length error, the hands' misses.
    written = flexkin.render(tmp_path / "tree.npz", tmp_path / "drawn", "plots")
    assert [pathlib.Path(p).name for p in written] == [
        "tree_" + plot + extension
        for plot in ("path_length", "length_error", "target_miss")
        for extension in (".svg", ".png")]


def test_a_pointing_goal_turns_its_link_onto_what_it_looks_at():
    # The arms' tree with the left arm's last link aimed: point 8's link from 7 points at a point.
    look = np.array([[-3.0, 4.0], [-2.0, 4.5], [-1.0, 5.0]])
    paths = [[ARMS[5] + [0.05 * k, 0.03 * k], look[k - 1]] for k in range(1, 4)]
    frames, report = flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], paths, fixed=[0],
                                        looks=[False, True])
    assert report["reached"].all()
    for f in range(1, 4):
        link = frames[f][8] - frames[f][7]
        toward = look[f - 1] - frames[f][7]
        np.testing.assert_allclose(link / np.linalg.norm(link), toward / np.linalg.norm(toward),
                                   atol=1e-9)
    with pytest.raises(flexkin.InputError) as error:
        flexkin.reach_tree(ARMS, ARM_PARENTS, [5, 8], paths, fixed=[0], looks=[False, True],
                           overall={"squared": 1.0})
    assert error.value.field == "targets[1]"


def test_a_robot_tree_runs_through_the_front_door(tmp_path):
    """A URDF robot tree (docs/trees.md, "Robot trees"): the two-armed robot's hands on their
    paths and its camera on the left hand, with the joint angles of every frame."""
    from conftest import EXAMPLES
    result = flexkin.run_scenario(EXAMPLES / "tree_robot_two_arms.json",
                                  output=tmp_path / "robot.npz")
    assert result["frames"].shape == (181, 17, 3)
    assert result["angles"].shape == (181, 15)
    assert result["joints"][0] == "waist"
    assert not any(result["prismatic"]) and result["sliding"] == []  # every joint turns
    assert result["reached"].all()
    assert result["max_length_error"] < 1e-14
    # No flips: the joints move little between frames.
    assert np.abs(np.diff(result["angles"], axis=0)).max() < 0.15
    with np.load(tmp_path / "robot.npz") as archive:
        np.testing.assert_array_equal(archive["angles"], result["angles"])
        np.testing.assert_array_equal(archive["frames"], result["frames"])
    # A robot tree's plots add its joint angles: one line a joint.
    written = flexkin.render(tmp_path / "robot.npz", tmp_path / "drawn", "plots")
    assert [pathlib.Path(p).name for p in written if p.endswith(".svg")] == [
        "robot_path_length.svg", "robot_length_error.svg", "robot_target_miss.svg",
        "robot_joint_angles.svg"]
    svg = (tmp_path / "drawn" / "robot_joint_angles.svg").read_text()
    paths = re.findall(r' d="([^"]*)"', svg)
    assert sum(1 for d in paths if d.count(" L ") >= 50) == 15
