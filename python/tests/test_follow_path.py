"""The follow_path method from Python: every joint on the head's path, its PathReport, and
path_deviation for any run (docs/colliders.md, "Follow the path")."""
import math
import subprocess

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES


def brute_distance(path, x):
    best = np.linalg.norm(x - path[0])
    for a, b in zip(path[:-1], path[1:]):
        d = b - a
        dd = d @ d
        t = min(max((x - a) @ d / dd, 0.0), 1.0) if dd > 0 else 0.0
        best = min(best, np.linalg.norm(x - (a + t * d)))
    return best


def wave():
    points = np.array([[-0.1 * i, 0.0] for i in range(9)])
    t = np.linspace(0.02, 4.0, 200)
    return points, np.column_stack([t, 0.3 * np.sin(2.0 * t)])


def test_joints_stay_on_the_head_path():
    points, targets = wave()
    result = flexkin.run(points, targets, method="follow_path", substeps=2)
    assert result.method == "follow_path"
    assert result.metrics.max_relative_length_error <= 1e-13
    report = result.path
    assert report.enabled
    assert report.deviation.shape == (200,) and report.tip_error.shape == (200,)
    assert report.max_deviation <= 1e-12
    assert math.isinf(report.least_clearance)
    for frame, step in list(zip(result.frames, result.steps))[::20]:
        path = np.vstack([points[::-1], targets[:step]])
        for x in frame:
            assert brute_distance(path, x) <= 1e-12
    assert "head's path" in result.brief_report()


def test_path_deviation_of_a_tractrix_run_cuts_the_corners():
    points, targets = wave()
    follow = flexkin.run(points, targets, method="follow_path")
    tractrix = flexkin.run(points, targets, method="tractrix")
    assert not tractrix.path.enabled
    mine = flexkin.path_deviation(points, targets, follow)
    theirs = flexkin.path_deviation(points, targets, tractrix)
    assert mine["deviation"].shape == (201, 9) and mine["tip_error"].shape == (201,)
    assert mine["deviation"].max() <= 1e-12
    assert theirs["deviation"].max() > 1e-3
    np.testing.assert_array_equal(mine["deviation"][1:].max(axis=1), follow.path.deviation)


def test_snake_example_clears_the_pegs_and_tractrix_does_not(cli, tmp_path):
    snake = flexkin.run_scenario(EXAMPLES / "snake_pegs.json")
    assert snake.path.least_clearance > 0.1
    assert snake.path.max_deviation <= 1e-12
    tractrix = flexkin.run_scenario(EXAMPLES / "snake_pegs_tractrix.json")
    assert tractrix.contacts.contact_link_steps > 0
    out = subprocess.run([cli, "run", str(EXAMPLES / "snake_pegs.json"), "-o",
                          str(tmp_path / "r.json")], capture_output=True, text=True, check=True)
    assert "least clearance" in out.stdout and "follow_path" in out.stdout


def test_refusals_name_the_field():
    points, targets = wave()
    with pytest.raises(flexkin.InputError) as error:
        flexkin.run(points, targets, method="follow_path", tolerance=1e-6)
    assert "tolerance" in str(error.value)
    with pytest.raises(flexkin.InputError):
        flexkin.move_leader(points, [0.1, 0.0], method="follow_path")
    folded = np.array([[0.0, 0.0], [-1.0, 0.0], [-0.1, 0.1]])
    with pytest.raises(flexkin.InputError) as error:
        flexkin.run(folded, [[0.25, 0.0], [0.5, 0.0]], method="follow_path")
    assert error.value.field == "leader_steps[0]"
