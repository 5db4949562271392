"""Argument checking: every bad input is an InputError (a ValueError) naming the argument."""
import numpy as np
import pytest

import flexkin

P = flexkin.parabola(a=1.0, links=5, link_length=0.25)
STEPS = flexkin.split_pull(P[0], [0.3, 0.1], 3)


def error(call, *args, **kwargs):
    with pytest.raises(flexkin.InputError) as info:
        call(*args, **kwargs)
    assert isinstance(info.value, ValueError)
    assert str(info.value).startswith(info.value.field)
    return info.value


@pytest.mark.parametrize("bad, field", [
    (np.zeros((4,)), "points"),                      # 1-D
    (np.zeros((4, 4)), "points"),                    # 4 columns
    (np.zeros((1, 2)), "points"),                    # one point: no link
    (np.zeros((0, 2)), "points"),                    # empty
    ([], "points"),
    (np.zeros((3, 2, 2)), "points"),                 # 3-D
    ([[0, 0], [1]], "points"),                       # ragged
    ([["a", "b"], ["c", "d"]], "points"),            # strings
    (np.array([[0, 0], [1, 0]], dtype=complex), "points"),
    (np.array([[0, 0], [1, 0]], dtype=object), "points"),
    (np.array([[True, False], [False, True]]), "points"),
    (None, "points"),
    ([[0.0, 0.0], [np.nan, 1.0]], "points[1][0]"),
    ([[0.0, 0.0], [1.0, np.inf]], "points[1][1]"),
    ([[0.0, 0.0], [0.0, 0.0]], "points[1]"),         # zero-length link
])
def test_bad_points(bad, field):
    e = error(flexkin.run, bad, STEPS)
    assert e.field.startswith(field)


@pytest.mark.parametrize("bad, field", [
    (np.zeros((0, 2)), "leader_steps"),
    (np.zeros((3, 3)), "leader_steps"),              # 3D steps for a 2D chain
    ([[1.0, -np.inf]], "leader_steps[0][1]"),
    ("steps", "leader_steps"),
])
def test_bad_leader_steps(bad, field):
    assert error(flexkin.run, P, bad).field.startswith(field)


@pytest.mark.parametrize("kwargs, field", [
    ({"substeps": 0}, "substeps"),
    ({"record_every": 0}, "record_every"),
    ({"tolerance": -1.0}, "tolerance"),
    ({"tolerance": float("nan")}, "tolerance"),
    ({"method": "tractrx"}, "method"),
    ({"method": "overall", "overall": {"l2": -1}}, "overall.weights.l2"),
    ({"method": "overall", "overall": {"bogus": 1}}, "bogus"),
    ({"overall": 3}, "overall"),
])
def test_bad_options(kwargs, field):
    assert error(flexkin.run, P, STEPS, **kwargs).field == field


def test_unknown_method_suggests():
    e = error(flexkin.run, P, STEPS, method="tractrx")
    assert "tractrix" in e.message and e.value


def test_noncontiguous_readonly_and_integer_arrays_accepted():
    ref = flexkin.run(P, STEPS)
    wide = np.zeros((P.shape[0], 4))
    wide[:, ::2] = P
    strided = wide[:, ::2]
    assert not strided.flags.c_contiguous
    fortran = np.asfortranarray(P)
    readonly = P.copy()
    readonly.flags.writeable = False
    for points in (strided, fortran, readonly, P.tolist(), tuple(map(tuple, P))):
        assert np.array_equal(flexkin.run(points, STEPS).frames, ref.frames)
    before = readonly.copy()
    flexkin.move_leader(readonly, [0.1, 0.1])
    assert np.array_equal(readonly, before)              # inputs are never changed
    ints = flexkin.run([[0, 0], [1, 0], [2, 0]], [[-1, 0]])
    assert ints.frames.dtype == np.float64


def test_curves_and_link_steps_check_their_arguments():
    assert error(flexkin.parabola, links=0).field == "links"
    assert error(flexkin.parabola, link_length=-1.0).field == "link_length"
    assert error(flexkin.arc, radius=0.01, link_length=1.0).field == "radius"
    assert error(flexkin.line, start=[0, 0], direction=[0, 0]).field == "direction"
    assert error(flexkin.line, start=[0, 0, 0], direction=[1, 0]).field == "direction"
    assert error(flexkin.helix, center=[0, 0]).field == "center"
    assert error(flexkin.tractrix_step, [0, 0], [1, 0], [0, 1], 0.0).field == "length"
    assert error(flexkin.tractrix_step, [0, 0], [1, 0, 0], [0, 1], 1.0).field == "head_new"
    assert error(flexkin.follow_the_leader_step, [0, 0], [np.nan, 0], [0, 1], 1.0).field == \
        "head_new[0]"
    assert error(flexkin.split_pull, [0, 0], [1, 0], 0).field == "steps"
    assert error(flexkin.resample_path, [0, 0], [[1, 0]], 0.0).field == "max_step"
    assert error(flexkin.move_leader, P, [1, 2, 3]).field == "target"
    assert error(flexkin.move_leader, P, [1, 2], substeps=0).field == "substeps"
    assert error(flexkin.move_leader, P, [1, 2], method="overall").field == "method"
    assert error(flexkin.Chain, P, link_length=0.3).field.startswith("points")


def test_scenario_errors():
    e = error(flexkin.run_scenario, {"curve": {"shape": "parabola", "links": 0},
                                      "leader": {"pull": [1, 0], "steps": 2}})
    assert e.field == "/curve/links"
    e = error(flexkin.run_scenario, {"leader": {"pull": [1, 0], "steps": 2}})
    assert e.field in ("", "/curve") and e.message
    assert error(flexkin.run_scenario, 42).field == "scenario"
    assert error(flexkin.run_scenario, {"curve": object()}).field == "scenario"
    assert error(flexkin.run_robot, {"arm": {}}).field.startswith("/")


READERS = [flexkin.run_scenario, flexkin.load_scenario, flexkin.validate_scenario,
           flexkin.run_robot, flexkin.load_robot_scenario, flexkin.read_result]
if hasattr(flexkin._flexkin, "arm_from_urdf"):
    READERS.append(flexkin.arm_from_urdf)


@pytest.mark.parametrize("reader", READERS, ids=lambda f: f.__name__)
def test_files_that_cannot_be_read_are_oserrors(reader, tmp_path):
    for missing in (tmp_path / "missing.json", str(tmp_path / "missing.json")):
        with pytest.raises(FileNotFoundError) as info:
            reader(missing)
        assert str(missing) in str(info.value)


def test_a_file_that_is_not_json_names_its_path(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"curve": ')
    e = error(flexkin.run_scenario, bad)
    assert str(bad) in str(e)
