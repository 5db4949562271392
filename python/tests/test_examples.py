"""The Python examples (examples/python, docs/python-examples.md) run, write their figures and
print the numbers of the C++ programs they mirror; the page's ```python blocks run."""
import os
import re
import shutil
import subprocess
import sys

import pytest

from conftest import EXAMPLES, SOURCE_DIR

SCRIPTS = SOURCE_DIR / "examples" / "python"
BUILD_DIR = os.environ.get("FLEXKIN_BUILD_DIR")
FIG06 = ["examples/fig06_parabola_multi_step.json", "examples/fig06_parabola_single_step.json",
         "examples/fig06_parabola_overall_multi_step.json",
         "examples/fig06_parabola_overall_single_step.json"]
PAGE = (SOURCE_DIR / "docs" / "python-examples.md").read_text()
PAGE_EXAMPLES = re.findall(r"```python\n(.*?)```", PAGE, flags=re.S)
NUMBER = r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"


def run_example(name, *args, timeout=120):
    """One example as a subprocess (this interpreter, PYTHONPATH inherited) from the source dir."""
    pytest.importorskip("matplotlib")   # Debian's python3-matplotlib (scripts/install-deps.sh)
    return subprocess.run([sys.executable, str(SCRIPTS / name), *map(str, args)], cwd=SOURCE_DIR,
                          capture_output=True, text=True, timeout=timeout)


def cpp_example(name):
    """A C++ example built in FLEXKIN_BUILD_DIR, or a skip saying why not."""
    if not BUILD_DIR:
        pytest.skip("FLEXKIN_BUILD_DIR is not set: no C++ example to compare with")
    path = os.path.join(BUILD_DIR, "examples", name)
    if not os.access(path, os.X_OK):
        pytest.skip(f"the C++ example {name} is not built ({path})")
    return path


@pytest.fixture(scope="module")
def flexkin_cli():
    """The command line: FLEXKIN_CLI, else FLEXKIN_BUILD_DIR/apps/flexkin, else the PATH's."""
    for path in (os.environ.get("FLEXKIN_CLI"),
                 BUILD_DIR and os.path.join(BUILD_DIR, "apps", "flexkin"),
                 shutil.which("flexkin")):
        if path and os.access(path, os.X_OK):
            return path
    pytest.skip("the flexkin command line is not built (FLEXKIN_CLI, FLEXKIN_BUILD_DIR)")


def assert_png(path):
    assert path.is_file(), f"{path} not written"
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert path.stat().st_size > 10000


@pytest.fixture(scope="module")
def fig06(tmp_path_factory):
    out = tmp_path_factory.mktemp("fig06")
    proc = run_example("fig06_compare.py", "--out", out)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout, out


def test_fig06_prints_the_comparison_and_draws(fig06):
    stdout, out = fig06
    lines = stdout.splitlines()
    assert lines[0].startswith(f"Fig. 6 / Sec. 5.1, reference {FIG06[0]}: L2 metric")
    assert len(lines) == 5 and lines[-1] == f"figure: {out / 'fig06_compare.png'}"
    for path, line in zip(FIG06[1:], lines[1:4]):
        method = "overall" if "overall" in path else "tractrix"
        m = re.fullmatch(rf"  {path} \({method}\): distance from the reference: sum over points "
                         rf"({NUMBER}), arc-length weighted ({NUMBER}), largest ({NUMBER}); L2 "
                         rf"metric of the motion ({NUMBER})", line)
        assert m, line
        total, weighted, largest, l2 = map(float, m.groups())
        # 21 points 0.25 apart (the weights): each sum bounds the next
        assert 0 < largest <= total and 0 < weighted <= 0.25 * total + 1e-6 and l2 > 0
    assert_png(out / "fig06_compare.png")


def test_fig06_matches_the_cpp_example(fig06):
    program = cpp_example("fig06_compare")
    cpp = subprocess.run([program, *FIG06], cwd=SOURCE_DIR, capture_output=True, text=True,
                         timeout=60)
    assert cpp.returncode == 0, cpp.stderr
    assert fig06[0].splitlines()[:4] == cpp.stdout.splitlines()


@pytest.fixture(scope="module")
def fig07(tmp_path_factory):
    out = tmp_path_factory.mktemp("fig07")
    proc = run_example("fig07_closed_form.py", "--out", out)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout, out


def without_clock(line):
    """The report line without its run time (`, 0.00081 s` at the end)."""
    return re.sub(rf", {NUMBER} s$", "", line)


def test_fig07_matches_the_closed_form(fig07):
    stdout, out = fig07
    line, figure = stdout.splitlines()
    m = re.match(rf"Fig\. 7 \(eq\. 23\): 501 frames, pull 5 link lengths; largest distance of the "
                 rf"trailing end from the closed form: ({NUMBER}) link lengths; tractrix: 1 links, "
                 rf"500 leader steps", line)
    assert m, line
    assert float(m.group(1)) < 1e-12
    assert figure == f"plot: {out / 'fig07_closed_form.png'}"
    assert_png(out / "fig07_closed_form.png")


def test_fig07_matches_the_cpp_example(fig07):
    program = cpp_example("fig07_closed_form")
    cpp = subprocess.run([program, "examples/fig07_straight_link.json"], cwd=SOURCE_DIR,
                         capture_output=True, text=True, timeout=60)
    assert cpp.returncode == 0, cpp.stderr
    assert without_clock(fig07[0].splitlines()[0]) == without_clock(cpp.stdout.strip())


def test_fig07_refuses_a_link_not_perpendicular(tmp_path):
    scenario = tmp_path / "slanted.json"
    scenario.write_text('{"curve": {"points": [[0, 0], [1, 1]]}, '
                        '"leader": {"pull": [-5, 0], "steps": 5}}')
    proc = run_example("fig07_closed_form.py", scenario, "--out", tmp_path)
    assert proc.returncode == 1 and "perpendicular" in proc.stderr


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    out = tmp_path_factory.mktemp("arm")
    proc = run_example("arm_circle.py", "--out", out)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout, out


def test_arm_tracks_the_circle(arm):
    stdout, out = arm
    assert re.match(r"200 steps, 0 not reached, max end-effector error", stdout)
    error = float(re.search(rf"from its target: ({NUMBER}) \(every target reached: True\)",
                            stdout).group(1))
    assert error < 1e-9
    rows = re.findall(rf"^ +(\d) +({NUMBER}) +({NUMBER}) +({NUMBER})", stdout, flags=re.M)
    assert [int(r[0]) for r in rows] == list(range(8))
    span = [float(r[1]) for r in rows]
    # The motion dies out toward the base: the base joint moves least, the last links most.
    assert span[0] == min(span) and span[-1] == max(span) and span[0] < 0.25 * span[-1]
    assert all(0 < float(r[2]) <= float(r[1]) <= float(r[3]) for r in rows)
    assert "the same arm in code (flexkin.ArmModel, flexkin.track_path): identical" in stdout
    assert_png(out / "arm_circle.png")
    lines = (out / "arm_circle_joints.csv").read_text().splitlines()
    assert lines[0] == "step," + ",".join(f"joint_{j}" for j in range(8)) and len(lines) == 202


def test_arm_joint_angles_are_those_of_the_command_line(arm, flexkin_cli, tmp_path):
    csv = tmp_path / "joints.csv"
    proc = subprocess.run([flexkin_cli, "robot", str(EXAMPLES / "robot_planar_8link.json"), "-o",
                           str(tmp_path / "robot.json"), "--csv", str(csv)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert (arm[1] / "arm_circle_joints.csv").read_text() == csv.read_text()
    # and the report, but for its clock
    assert without_clock(arm[0].splitlines()[0]) == without_clock(proc.stdout.splitlines()[0])


def test_dask_sweep_example_runs(tmp_path):
    pytest.importorskip("distributed")   # Debian's python3-distributed
    # 200 of the 1,000 variations, 10 to a task (test_dask.py runs all 1,000, one to a task)
    proc = run_example("dask_sweep.py", "--count", 200, "--batch", 10)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "dask.distributed (LocalCluster of 2 worker processes, 10 variations per task)" \
        in proc.stdout
    assert proc.stdout.rstrip().endswith(
        "identical: every result of the cluster equals the serial one bit for bit")
    assert "serial (this process): " in proc.stdout and proc.stderr == ""


def test_the_page_has_a_runnable_example():
    assert len(PAGE_EXAMPLES) >= 1


@pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")
@pytest.mark.parametrize("index", range(len(PAGE_EXAMPLES)))
def test_page_example_runs(index, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.chdir(SOURCE_DIR)
    exec(compile(PAGE_EXAMPLES[index], f"docs/python-examples.md example {index + 1}", "exec"),
         {"__name__": "__main__"})


def test_tree_figure_draws_a_tree_result(tmp_path, flexkin_cli):
    """examples/python/tree_figure.py (run by make demo) draws a tree result read with numpy."""
    result = tmp_path / "tree_two_arms.npz"
    subprocess.run([flexkin_cli, "run", str(EXAMPLES / "tree_two_arms.json"), "-o", str(result)],
                   check=True, capture_output=True, timeout=120)
    out = run_example("tree_figure.py", result, "--out", tmp_path / "tree.png")
    assert out.returncode == 0, out.stderr
    assert_png(tmp_path / "tree.png")
    assert "61 frames" in out.stdout


def test_the_robot_tree_example_is_what_its_script_writes(tmp_path):
    """examples/robot_two_arms.urdf and examples/tree_robot_two_arms.json are written by
    examples/python/make_robot_two_arms.py: run again, it writes the same bytes."""
    result = subprocess.run([sys.executable, str(SCRIPTS / "make_robot_two_arms.py"), str(tmp_path)],
                            cwd=SOURCE_DIR, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    for name in ["robot_two_arms.urdf", "tree_robot_two_arms.json"]:
        assert (tmp_path / name).read_bytes() == (EXAMPLES / name).read_bytes(), name
