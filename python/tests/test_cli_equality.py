"""flexkin.run_scenario and run_robot give the command line's results bit for bit."""
import json
import subprocess

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES

CHAIN_SCENARIOS = sorted(EXAMPLES.glob("fig*.json"))
ROBOT_SCENARIOS = sorted(EXAMPLES.glob("robot_*.json"))


def same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("path", CHAIN_SCENARIOS, ids=lambda p: p.stem)
def test_run_scenario_equals_cli(path, cli, tmp_path):
    out = tmp_path / "result.npz"
    subprocess.run([cli, "run", str(path), "-o", str(out), "-q"], check=True)
    with np.load(out) as cli_result:
        files = {key: cli_result[key] for key in cli_result.files}
    info = json.loads(bytes(files["result.json"]))
    with open(path) as f:
        as_dict = json.load(f)
    for scenario in (path, str(path), as_dict):
        res = flexkin.run_scenario(scenario)
        assert same_bits(res.frames, files["frames"])
        assert same_bits(res.steps, files["steps"])
        if "link_angles" in files:
            assert same_bits(res.link_angles, files["link_angles"])
        else:
            assert res.link_angles is None
        assert same_bits(res.lengths, files["link_lengths"])
        assert same_bits(res.metrics.l2_per_step, files["l2_per_step"])
        assert same_bits(res.metrics.l2_weighted_per_step, files["l2_weighted_per_step"])
        assert same_bits(res.metrics.path_length, files["path_length"])
        for key in ("l2_total", "l2_weighted_total", "max_relative_length_error"):
            assert getattr(res.metrics, key) == info["metrics"][key], key
        assert res.method == info["method"]
        assert res.num_steps == info["num_steps"]
        assert res.substeps == info["substeps"]
        assert res.dim == info["dim"]
        assert res.scenario == info.get("scenario", "")


@pytest.mark.parametrize("path", ROBOT_SCENARIOS, ids=lambda p: p.stem)
def test_run_robot_equals_cli(path, cli, tmp_path):
    out = tmp_path / "trajectory.json"
    done = subprocess.run([cli, "robot", str(path), "-o", str(out), "-q"], check=False,
                          capture_output=True, text=True)
    with open(out) as f:
        cli_result = json.load(f)
    # The exit status: 0, or 3 when a target was not reached (the file is written either way).
    assert done.returncode == (3 if cli_result["summary"]["unreached"] else 0), done.stderr
    traj = flexkin.run_robot(path)
    steps = cli_result["steps"]
    assert traj.num_steps == len(steps) == traj.angles.shape[0]
    n = len(cli_result["link_lengths"])
    assert traj.angles.shape == (len(steps), n)
    # One point per distinct position, as the file has them (joints at one point share theirs).
    assert traj.points.shape == (len(steps), len(steps[0]["points"]), cli_result["dim"])
    assert same_bits(traj.angles, np.array([s["joint_angles"] for s in steps], dtype=float))
    assert same_bits(traj.points, np.array([s["points"] for s in steps], dtype=float))
    assert same_bits(traj.path, np.array([s["target"] for s in steps], dtype=float))
    assert same_bits(traj.ee_error, np.array([s["ee_error"] for s in steps], dtype=float))
    assert same_bits(traj.base_error, np.array([s["base_error"] for s in steps], dtype=float))
    for key in ("iterations", "sweeps", "legs", "restarts", "reached", "stretched", "limited",
                "joint_space"):
        assert getattr(traj, key).tolist() == [s[key] for s in steps], key
    for key in ("pointing_error", "velocity_ratio", "velocity_legs"):   # where the file has them
        if key in steps[0]:
            assert getattr(traj, key).tolist() == [s[key] for s in steps], key
    assert same_bits(traj.initial_angles,
                     np.array(cli_result["initial"]["joint_angles"], dtype=float))
    assert traj.unreached == cli_result["summary"]["unreached"]
    if "joint_azimuths" in steps[0]:
        assert same_bits(traj.azimuths, np.array([s["joint_azimuths"] for s in steps], dtype=float))
    # The same from the dict form, the URDF looked up beside the file.
    with open(path) as f:
        as_dict = json.load(f)
    again = flexkin.run_robot(as_dict, directory=path.parent)
    assert same_bits(again.angles, traj.angles)
    assert same_bits(again.points, traj.points)


def without_seconds(value):
    """A parsed trajectory with its timings left out (they differ from run to run)."""
    if isinstance(value, dict):
        return {k: without_seconds(v) for k, v in value.items() if k != "seconds"}
    if isinstance(value, list):
        return [without_seconds(v) for v in value]
    return value


@pytest.mark.parametrize("path", ROBOT_SCENARIOS, ids=lambda p: p.stem)
def test_run_robot_files_equal_cli(path, cli, tmp_path):
    # `flexkin run` of a robot scenario is `flexkin robot` (the same files, the same status).
    done = subprocess.run([cli, "run", str(path), "-o", str(tmp_path / "cli.json"), "--csv",
                           str(tmp_path / "cli.csv"), "-q"], check=False, capture_output=True,
                          text=True)
    traj = flexkin.run_robot(path, output=tmp_path / "py.json", csv=tmp_path / "py.csv")
    assert done.returncode == (3 if traj.unreached else 0), done.stderr
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    with open(tmp_path / "cli.json") as a, open(tmp_path / "py.json") as b:
        assert without_seconds(json.load(a)) == without_seconds(json.load(b))


@pytest.mark.parametrize("path", CHAIN_SCENARIOS[:3], ids=lambda p: p.stem)
def test_result_csv_equals_cli(path, cli, tmp_path):
    subprocess.run([cli, "run", str(path), "-o", str(tmp_path / "r.json"), "--csv",
                    str(tmp_path / "cli.csv"), "-q"], check=True)
    flexkin.run_scenario(path).write_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
