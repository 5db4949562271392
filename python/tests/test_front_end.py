"""The module as a Python front end (issue 24): the curve generators take a scenario file's
"curve" fields, an unknown keyword is named with the nearest valid one (never with the
arguments' values), inspect.signature works for every public callable, __version__ is the
command's, and files of the wrong kind or in the wrong place say so."""
import inspect
import json
import os
import subprocess
import warnings

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES, SOURCE_DIR

# ---------------------------------------------------------------------------------------------
# The curve generators and the scenario file's "curve"


def curve_from_file(curve):
    """The chain's points of a scenario whose "curve" is `curve`, read by the library's parser."""
    dim = len(curve.get("start", curve.get("direction", [0, 0])))
    dim = 3 if curve["shape"] == "helix" else dim
    scenario = {"curve": curve, "leader": {"pull": [0.1] * dim}}
    return flexkin.load_scenario(scenario).chain.points


FILE_CURVES = [
    {"shape": "arc", "radius": 1, "turn": "cw", "links": 7, "link_length": 0.3},
    {"shape": "arc", "radius": 2, "center": [1, -1], "start_angle": 0.5, "turn": "ccw",
     "links": 5, "link_length": 0.25},
    {"shape": "parabola", "a": 0.5, "side": "-x", "links": 6, "link_length": 0.25},
    {"shape": "parabola", "a": 1, "side": "+x", "links": 6, "link_length": 0.25},
    {"shape": "helix", "radius": 1, "pitch": -0.5, "turn": "cw", "links": 6, "link_length": 0.4},
    {"shape": "line", "start": [0, 0, 0], "links": 3, "link_length": 0.5},
    {"shape": "line", "direction": [0, 1, 1], "links": 3, "link_length": 0.5},
    {"shape": "line", "start": [1, 2], "direction": [-1, 0], "links": 2, "link_length": 1},
    {"shape": "line", "links": 2, "link_length": 1},
]


@pytest.mark.parametrize("curve", FILE_CURVES, ids=lambda c: json.dumps(c, sort_keys=True))
def test_generators_take_the_file_curve_fields(curve):
    fields = {k: v for k, v in curve.items() if k != "shape"}
    points = getattr(flexkin, curve["shape"])(**fields)
    assert np.array_equal(points, curve_from_file(curve))


def test_line_from_a_3d_start_defaults_to_plus_x():
    points = flexkin.line(start=[0, 0, 0], links=3)
    assert points.shape == (4, 3)
    assert np.array_equal(points[:, 1:], np.zeros((4, 2))) and points[-1, 0] == pytest.approx(0.3)
    assert flexkin.line(direction=[0, 0, 2], links=1).shape == (2, 3)      # from the origin
    assert flexkin.line().shape == (11, 2)


@pytest.mark.parametrize("shape, keyword, bad, fields", [
    ("arc", "turn", "clockwise", {"radius": 1}),
    ("helix", "turn", "CW", {"radius": 1, "pitch": 1}),
    ("parabola", "side", "x", {"a": 1}),
])
def test_a_bad_curve_value_is_named_with_what_the_file_accepts(shape, keyword, bad, fields):
    with pytest.raises(flexkin.InputError) as info:
        getattr(flexkin, shape)(**fields, **{keyword: bad})
    error = info.value
    assert error.field == keyword and error.value == f'"{bad}"'
    assert keyword in str(error) and f'"{bad}"' in str(error)
    # the same names as the scenario file's reader accepts
    curve = {"shape": shape, "links": 2, "link_length": 0.1, **fields, keyword: bad}
    problems = flexkin.validate_scenario({"curve": curve, "leader": {"pull": [0.1, 0.1]}})
    assert [p["field"] for p in problems][:1] == [f"/curve/{keyword}"]
    file_expected = problems[0]["expected"]
    assert error.expected and file_expected.endswith(error.expected), (file_expected, error)
    assert error.expected in str(error)
    with pytest.raises(flexkin.InputError, match=keyword):
        getattr(flexkin, shape)(**fields, **{keyword: 1.5})          # not a str


def test_the_old_curve_keywords_still_work_with_a_warning():
    with pytest.warns(DeprecationWarning, match="turn="):
        old = flexkin.arc(clockwise=True, links=4)
    assert np.array_equal(old, flexkin.arc(turn="cw", links=4))
    with pytest.warns(DeprecationWarning):
        old = flexkin.helix(clockwise=False, links=4)
    assert np.array_equal(old, flexkin.helix(links=4))
    with pytest.warns(DeprecationWarning, match='side="-x"'):
        old = flexkin.parabola(side=-1, links=4)
    assert np.array_equal(old, flexkin.parabola(side="-x", links=4))
    with pytest.raises(flexkin.InputError, match="clockwise"), warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        flexkin.arc(turn="cw", clockwise=False)
    with pytest.raises(flexkin.InputError, match="side"):
        flexkin.parabola(side=2)


# ---------------------------------------------------------------------------------------------
# Unknown keywords


def public_callables():
    """(name, object) of every public function and constructible class."""
    for name in flexkin.__all__:
        obj = getattr(flexkin, name)
        if isinstance(obj, type) and issubclass(obj, BaseException):
            continue
        yield name, obj


def keyword_parameters(obj):
    return [p.name for p in inspect.signature(obj).parameters.values()
            if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def takes_any_keyword(obj):
    return any(p.kind == p.VAR_KEYWORD for p in inspect.signature(obj).parameters.values())


# Each function and class taking named keywords, with its last keyword (misspelt in the test).
TYPO_CASES = [(name, keyword) for name, obj in public_callables() if not takes_any_keyword(obj)
              for keyword in keyword_parameters(obj)[-1:]]


def test_every_keyword_taking_front_door_is_checked():
    names = {name for name, _ in TYPO_CASES}
    for name in ("run", "run_scenario", "run_robot", "track_path", "run_groom", "RunOptions",
                 "ArmOptions", "StrandOptions", "Chain", "arc", "line"):
        assert name in names, name
    if hasattr(flexkin._flexkin, "render"):
        assert {"render", "FigureOptions", "GltfOptions", "ViewerOptions"} <= names


@pytest.mark.parametrize("name, keyword", TYPO_CASES)
def test_an_unknown_keyword_names_the_nearest_one(name, keyword):
    typo = keyword[:-1] if len(keyword) > 3 else keyword + "x"
    with pytest.raises(TypeError) as info:
        getattr(flexkin, name)(**{typo: 1})
    error = info.value
    assert isinstance(error, flexkin.InputError) and isinstance(error, flexkin.KeywordError)
    text = str(error)
    assert f'unknown keyword "{typo}"; did you mean "{keyword}"?' in text, text
    for valid in keyword_parameters(getattr(flexkin, name)):
        assert f'"{valid}"' in error.expected and f'"{valid}"' in text
    assert error.field == typo and error.value == f'"{typo}"'
    assert text.startswith(f"flexkin.{name}(): ")


def test_a_keyword_typo_does_not_print_the_arrays():
    points = flexkin.parabola(links=2000, link_length=0.001)
    steps = flexkin.split_pull(points[0], [0.1, 0.1], 500)
    with pytest.raises(TypeError) as info:
        flexkin.run(points, steps, substep=4)
    text = str(info.value)
    assert text == ('flexkin.run(): unknown keyword "substep"; did you mean "substeps"? Expected '
                    'one of "points", "leader_steps", "method", "substeps", "record_every", '
                    '"tolerance", "max_substeps", "link_angles", "overall", "colliders", '
                    '"link_radius" or "progress"')
    with pytest.raises(TypeError) as info:                  # a value of the wrong type
        flexkin.run(points, steps, substeps="four")
    text = str(info.value)
    assert "substeps='four' (str)" in text and "shape (2001, 2)" in text and len(text) < 1200
    with pytest.raises(TypeError, match="missing a required argument: 'leader_steps'"):
        flexkin.run(points)
    with pytest.raises(TypeError) as info:
        flexkin.Chain(points, link_lenght=0.001)
    assert "did you mean \"link_length\"?" in str(info.value) and len(str(info.value)) < 200


def test_a_keyword_with_no_near_miss_lists_the_valid_ones():
    with pytest.raises(flexkin.KeywordError) as info:
        flexkin.split_pull([0, 0], [1, 1], 3, colour="red")
    assert str(info.value) == ('flexkin.split_pull(): unknown keyword "colour"; expected one of '
                               '"start", "pull" or "steps"')


def test_keyword_checks_leave_good_calls_and_their_errors_alone():
    pts = flexkin.parabola(links=4)
    res = flexkin.run(pts, [[0.1, 0.1]], substeps=2, progress=lambda done, total: None)
    assert res.accuracy.substeps == 2
    with pytest.raises(ZeroDivisionError):                 # raised by progress, not refused
        flexkin.run(pts, [[0.1, 0.1]] * 3, progress=lambda done, total: 1 / 0)
    with pytest.raises(TypeError, match="mine"):
        def progress(done, total):
            raise TypeError("mine")
        flexkin.run(pts, [[0.1, 0.1]] * 3, progress=progress)
    with pytest.raises(flexkin.InputError, match="substeps"):
        flexkin.run(pts, [[0.1, 0.1]], substeps=0)


# ---------------------------------------------------------------------------------------------
# inspect.signature


@pytest.mark.parametrize("name", flexkin.__all__)
def test_every_public_callable_has_a_signature(name):
    obj = getattr(flexkin, name)
    signature = inspect.signature(obj)
    builtin = getattr(flexkin._flexkin, name, None)
    if builtin is None or isinstance(obj, type):
        return
    # a function: the C++ parameters, in order, with their defaults as values
    first = builtin.__doc__.splitlines()[0]
    assert first.startswith(name + "(")
    for parameter in signature.parameters.values():
        assert parameter.kind not in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD), name
        assert parameter.name in first
        assert parameter.annotation is not inspect.Parameter.empty, (name, parameter)
        if parameter.default is not inspect.Parameter.empty:
            assert f"{parameter.name}: " in first and " = " in first


def test_signatures_give_the_defaults_as_values():
    assert str(inspect.signature(flexkin.arc)).startswith(
        "(*, radius: float = 1.0, center: 'ArrayLike' = [0.0, 0.0], start_angle: float = 0.0, "
        "turn: str = 'ccw', links: int = 10")
    run = inspect.signature(flexkin.run).parameters
    assert list(run)[:2] == ["points", "leader_steps"]
    assert run["points"].kind == inspect.Parameter.POSITIONAL_OR_KEYWORD
    assert run["substeps"].kind == inspect.Parameter.KEYWORD_ONLY
    assert (run["method"].default, run["substeps"].default, run["overall"].default) == (
        "tractrix", 1, None)
    assert "bool" in run["progress"].annotation       # progress=True works
    assert list(inspect.signature(flexkin.Chain).parameters) == ["points", "link_length",
                                                                  "lengths"]
    assert inspect.signature(flexkin.RunOptions).parameters["max_substeps"].default == 65536
    bound = inspect.signature(flexkin.parabola).bind(a=2.0, side="-x")
    assert bound.arguments == {"a": 2.0, "side": "-x"}


def test_option_class_signatures_are_their_fields_and_defaults():
    for name in ("FigureOptions", "PlotOptions", "AnimationOptions", "ViewerOptions",
                 "GltfOptions"):
        cls = getattr(flexkin._flexkin, name, None)
        if cls is None:
            continue
        parameters = inspect.signature(cls).parameters
        defaults = cls()
        assert parameters and all(p.kind == p.KEYWORD_ONLY for p in parameters.values())
        for parameter in parameters.values():
            assert getattr(defaults, parameter.name) == parameter.default, (name, parameter)
        assert cls(**{p.name: p.default for p in parameters.values()}) == defaults
    assert "terms" in str(inspect.signature(flexkin.ObjectiveWeights))


def test_wrapped_functions_and_classes_behave_as_before():
    import pickle
    assert flexkin.run.__name__ == "run" and flexkin.run.__module__ == "flexkin"
    assert pickle.loads(pickle.dumps(flexkin.run)) is flexkin.run
    assert "progress=True" in flexkin.run.__doc__ and "leader_steps" in flexkin.run.__doc__
    chain = flexkin.Chain(flexkin.parabola(links=3), link_length=0.25)
    assert isinstance(chain, flexkin._flexkin.Chain)
    assert pickle.loads(pickle.dumps(chain)) == chain

    class Mine(flexkin.Chain):
        pass

    assert Mine(flexkin.parabola(links=3)).num_links == 3


# ---------------------------------------------------------------------------------------------
# __version__


def test_version_is_the_commands(cli):
    out = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.strip() == f"flexkin {flexkin.__version__}"


def test_version_is_the_projects():
    assert isinstance(flexkin.__version__, str) and flexkin.__version__.count(".") == 2
    cmake = (SOURCE_DIR / "CMakeLists.txt").read_text()
    assert f"project(flexkin VERSION {flexkin.__version__} " in cmake
    pyproject = (SOURCE_DIR / "pyproject.toml").read_text()
    assert f'version = "{flexkin.__version__}"' in pyproject


# ---------------------------------------------------------------------------------------------
# A robot scenario dict whose "urdf" is relative


needs_urdf = pytest.mark.skipif(not hasattr(flexkin._flexkin, "arm_from_urdf"),
                                reason="the URDF component is not built")


@needs_urdf
@pytest.mark.parametrize("name", ["run_robot", "load_robot_scenario", "validate_scenario"])
def test_a_relative_urdf_of_a_dict_names_the_field_the_path_and_directory(name, tmp_path,
                                                                          monkeypatch):
    scenario = json.loads((EXAMPLES / "robot_snake_urdf.json").read_text())
    scenario["path"]["steps"] = 2
    monkeypatch.chdir(tmp_path)
    with pytest.raises(FileNotFoundError) as info:
        getattr(flexkin, name)(scenario)
    text = str(info.value)
    tried = os.path.join(str(tmp_path), "robot_snake.urdf")
    assert "/urdf" in text and '"robot_snake.urdf"' in text and tried in text, text
    assert "working directory" in text and "directory=" in text and "absolute path" in text
    assert info.value.filename == tried
    assert getattr(flexkin, name)(scenario, directory=EXAMPLES) is not None
    scenario["urdf"] = str(EXAMPLES / "robot_snake.urdf")
    assert getattr(flexkin, name)(scenario) is not None
    scenario["urdf"] = str(tmp_path / "absent.urdf")
    with pytest.raises(FileNotFoundError) as info:            # absolute: the library's error
        getattr(flexkin, name)(scenario)
    assert "directory=" not in str(info.value)


# ---------------------------------------------------------------------------------------------
# Grooms: a strand file read as a result, overrides of the file's fields


GROOM = {"groom": {"scalp": {"shape": "sphere", "center": [0, 0, 0], "radius": 0.1},
                   "roots": 3, "links": 2, "link_length": 0.01, "seed": 1},
         "motion": {"fps": 10, "keyframes": [
             {"time": 0}, {"time": 0.2, "translation": [0.01, 0, 0]}]}}


def test_read_result_of_a_strand_file_says_what_reads_it(tmp_path):
    path = tmp_path / "hair.npz"
    flexkin.run_groom(GROOM, path)
    with pytest.raises(flexkin.InputError) as info:
        flexkin.read_result(path)
    text = str(info.value)
    assert info.value.field == str(path)
    assert "is a strand file" in text and "numpy.load" in text, text
    assert "result.json" not in text and "missing" not in text
    assert "points" in np.load(path).files                 # what the message says reads it


def test_groom_overrides_say_what_is_valid_as_the_file_does(tmp_path):
    out = tmp_path / "hair.npz"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.run_groom(GROOM, out, precision="double")
    error = info.value
    assert error.field == "precision" and error.value == '"double"'
    assert '"float32" or "float64"' in str(error) and '"double"' in str(error)
    problems = flexkin.validate_scenario(dict(GROOM, record={"precision": "double"}))
    assert problems[0]["field"] == "/record/precision"
    assert problems[0]["expected"].endswith(error.expected)
    with pytest.raises(flexkin.InputError, match='precision: value 64 is not valid'):
        flexkin.run_groom(GROOM, out, precision=64)
    for keyword, value in (("substeps", 2.5), ("threads", "2"), ("pinned", True),
                           ("record_every", 2 ** 40)):
        with pytest.raises(flexkin.InputError) as info:
            flexkin.run_groom(GROOM, out, **{keyword: value})
        assert info.value.field == keyword and repr(value) in str(info.value)
        assert "integer" in info.value.expected
    for keyword, value, expected in (("substeps", 0, "an integer >= 1"),
                                     ("record_every", 0, "an integer >= 1"),
                                     ("threads", -1, "an integer from 0 to 1024")):
        with pytest.raises(flexkin.InputError) as info:
            flexkin.run_groom(GROOM, out, **{keyword: value})
        assert info.value.field == keyword and info.value.expected == expected
    assert not out.exists()
    report = flexkin.run_groom(GROOM, out, precision="float64", substeps=np.int64(2))
    assert report.max_length_error < 1e-12 and np.load(out)["points"].dtype == np.float64


# The front door (flexkin/any_scenario.h): a change to a library reader reaches Python and the
# command line with neither touched. A key given twice, refused by the JSON reader alone, is one
# problem at the same pointer in both.
def test_a_file_problem_reaches_python_and_the_command_line_alike(tmp_path, cli):
    path = tmp_path / "twice.json"
    path.write_text('{"curve": {"shape": "line", "links": 25, "links": 30, "link_length": 1},'
                    ' "leader": {"pull": [1, 0]}}')
    problems = flexkin.validate_scenario(str(path))
    assert [p["field"] for p in problems] == ["/curve/links"]
    assert '"links" appears more than once' in problems[0]["message"]
    out = subprocess.run([cli, "validate", str(path)], capture_output=True, text=True)
    assert out.returncode == 1
    assert out.stdout == "%s: /curve/links: %s\n" % (path, problems[0]["message"])
    # Every kind is told apart by the library: a groom file given to run_scenario runs as a
    # groom, into the file it needs; a groom given to load_scenario (chains only) is named.
    with pytest.raises(flexkin.InputError, match="required for a groom scenario"):
        flexkin.run_scenario(str(EXAMPLES / "groom_grass_2d.json"))
    with pytest.raises(flexkin.InputError, match="is a groom scenario, not a chain one"):
        flexkin.load_scenario(str(EXAMPLES / "groom_grass_2d.json"))


# A scenario option added in the library only (the leader's "closed": true, src/io/
# scenario_sections.cc) reaches Python and the command line without a change to either.
CLOSED = {"curve": {"points": [[0.25, 0.5], [0, 0.5], [-0.5, 0.5]]},
          "leader": {"path": [[1, 0.5], [1, 1.5]], "closed": True}}


def test_a_library_option_reaches_python_untouched():
    scenario = flexkin.load_scenario(CLOSED)
    assert scenario.leader_steps.shape == (3, 2)
    assert list(scenario.leader_steps[-1]) == [0.25, 0.5]
    result = flexkin.run_scenario(CLOSED)
    assert list(result.frames[-1, 0]) == [0.25, 0.5]
    bad = dict(CLOSED, leader={"pull": [1, 0], "closed": True})
    assert [p["field"] for p in flexkin.validate_scenario(bad)] == ["/leader/closed"]


def test_a_library_option_reaches_the_command_line_untouched(cli, tmp_path):
    import json
    import subprocess
    path = tmp_path / "closed.json"
    path.write_text(json.dumps(CLOSED))
    subprocess.run([cli, "run", str(path), "-o", str(tmp_path / "r.npz"), "-q"], check=True)
    frames = flexkin.read_result(tmp_path / "r.npz").frames
    assert np.array_equal(frames, flexkin.run_scenario(CLOSED).frames)
    path.write_text(json.dumps(dict(CLOSED, leader={"pull": [1, 0], "closed": True})))
    done = subprocess.run([cli, "validate", str(path)], capture_output=True, text=True)
    assert done.returncode != 0 and "/leader/closed" in done.stderr + done.stdout


def test_run_scenario_runs_every_kind_through_the_library(tmp_path):
    # One Python entry for every kind, over the library's one call (RunScenarioToFiles): a chain
    # to a Result, a robot to a RobotResult, a groom into its strand file.
    chain = flexkin.run_scenario(EXAMPLES / "fig10_planar_curve.json")
    assert isinstance(chain, flexkin.Result)
    robot = flexkin.run_scenario(EXAMPLES / "robot_planar_8link.json",
                                 output=tmp_path / "arm.json", csv=tmp_path / "arm.csv")
    assert isinstance(robot, flexkin.RobotResult) and (tmp_path / "arm.csv").exists()
    same = flexkin.run_robot(EXAMPLES / "robot_planar_8link.json")
    assert np.array_equal(robot.points, same.points)
    report = flexkin.run_scenario(EXAMPLES / "groom_grass_2d.json", output=tmp_path / "g.npz")
    assert report.max_length_error < 1e-12
    flexkin.run_groom(EXAMPLES / "groom_grass_2d.json", tmp_path / "g2.npz")
    a, b = np.load(tmp_path / "g.npz"), np.load(tmp_path / "g2.npz")
    assert np.array_equal(a["points"], b["points"])
    with pytest.raises(flexkin.InputError) as info:
        flexkin.run_scenario(EXAMPLES / "groom_grass_2d.json")
    assert info.value.field == "output"
    with pytest.raises(flexkin.InputError) as info:
        flexkin.run_scenario(EXAMPLES / "groom_grass_2d.json", output=tmp_path / "g.npz",
                             csv=tmp_path / "g.csv")
    assert info.value.field.endswith("csv")


# ---------------------------------------------------------------------------------------------
# Colliders through the front door (docs/colliders.md)


def test_a_scenarios_colliders_keep_the_rope_outside_the_post():
    with open(os.path.join(EXAMPLES, "rope_round_post.json")) as f:
        scenario = json.load(f)
    post = scenario["colliders"][0]
    center, radius = np.array(post["center"]), post["radius"]
    for method in ("tractrix", "ftl"):
        scenario["method"] = method
        result = flexkin.run_scenario(scenario)
        assert result.contacts.num_colliders == 1
        assert result.contacts.contact_link_steps > 0
        assert result.contacts.least_clearance >= -1e-13
        # Every link of every frame sampled at 101 points: outside the disc to 1e-12 of a link.
        a, b = result.frames[:, :-1, None, :], result.frames[:, 1:, None, :]
        t = np.linspace(0.0, 1.0, 101)[None, None, :, None]
        distance = np.linalg.norm(a + t * (b - a) - center, axis=-1) - radius
        assert distance.min() >= -1e-12 * 0.05, method
    del scenario["colliders"]
    free = flexkin.run_scenario(scenario)
    assert free.contacts.num_colliders == 0
    assert (np.linalg.norm(free.frames - center, axis=-1) - radius).min() < -0.1 * radius


def test_a_bad_collider_is_named_by_its_json_pointer():
    with open(os.path.join(EXAMPLES, "rope_round_post.json")) as f:
        scenario = json.load(f)
    scenario["colliders"].append({"shape": "capsule", "from": [5, 5], "to": [6, 5], "radius": -1})
    with pytest.raises(flexkin.InputError) as error:
        flexkin.run_scenario(scenario)
    assert "/colliders/1/radius" in str(error.value)
