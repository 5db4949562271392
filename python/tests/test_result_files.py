"""Result files from Python: read_result, Result.write / write_result, validate_scenario,
estimate_output."""
import json
import subprocess

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES


def same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def assert_same_result(a, b):
    for key in ("frames", "steps", "lengths"):
        assert same_bits(getattr(a, key), getattr(b, key)), key
    if a.link_angles is None:
        assert b.link_angles is None
    else:
        assert same_bits(a.link_angles, b.link_angles)
    for key in ("l2_per_step", "l2_weighted_per_step", "path_length"):
        assert same_bits(getattr(a.metrics, key), getattr(b.metrics, key)), key
    for key in ("l2_total", "l2_weighted_total", "max_relative_length_error"):
        assert getattr(a.metrics, key) == getattr(b.metrics, key), key
    assert (a.method, a.num_steps, a.substeps, a.dim, a.scenario) == (
        b.method, b.num_steps, b.substeps, b.dim, b.scenario)


@pytest.mark.parametrize("ext", ["json", "npz", "NPZ"])
def test_round_trip_bit_for_bit(tmp_path, ext):
    res = flexkin.run_scenario(EXAMPLES / "fig12_spatial_curve.json")
    path = tmp_path / ("result." + ext)
    res.write(path)
    assert_same_result(flexkin.read_result(path), res)
    other = tmp_path / ("again." + ext)
    flexkin.write_result(res, str(other))
    assert_same_result(flexkin.read_result(str(other)), res)
    if ext == "json":
        assert json.loads(path.read_text())["format"] == "flexkin-result"
    else:
        assert path.read_bytes()[:4] == b"PK\x03\x04"


def test_round_trip_without_link_angles(tmp_path):
    res = flexkin.run(flexkin.parabola(links=6), [[0.1, 0.0], [0.1, 0.1]], link_angles=False)
    res.write(tmp_path / "r.npz")
    back = flexkin.read_result(tmp_path / "r.npz")
    assert back.link_angles is None and same_bits(back.frames, res.frames)


def test_cli_npz_read_equals_run_scenario(cli, tmp_path):
    path = EXAMPLES / "fig10_planar_curve.json"
    out = tmp_path / "cli.npz"
    subprocess.run([cli, "run", str(path), "-o", str(out), "-q"], check=True)
    assert_same_result(flexkin.read_result(out), flexkin.run_scenario(path))


def test_read_errors(tmp_path):
    missing = tmp_path / "missing.npz"
    with pytest.raises(OSError, match="missing.npz"):
        flexkin.read_result(missing)
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "flexkin-result", "version": 1, "dim": 7}')
    with pytest.raises(flexkin.InputError) as info:
        flexkin.read_result(bad)
    assert "bad.json" in info.value.field
    res = flexkin.run(flexkin.parabola(links=4), [[0.1, 0.0]])
    good = tmp_path / "good.npz"
    res.write(good)
    data = good.read_bytes()
    corrupt = tmp_path / "corrupt.npz"
    corrupt.write_bytes(data[:len(data) // 2])  # truncated
    with pytest.raises(flexkin.InputError, match="corrupt.npz"):
        flexkin.read_result(corrupt)
    import zipfile
    with zipfile.ZipFile(good) as z:
        member = z.getinfo("frames.npy")
    flipped = bytearray(data)
    flipped[member.header_offset + 100] ^= 0xFF  # inside frames.npy's data: its CRC-32 fails
    corrupt.write_bytes(bytes(flipped))
    with pytest.raises(flexkin.InputError, match="frames.npy"):
        flexkin.read_result(corrupt)
    text = tmp_path / "text.json"
    text.write_text("not json")
    with pytest.raises(flexkin.InputError, match="text.json"):
        flexkin.read_result(text)


def test_write_is_all_or_nothing(tmp_path):
    res = flexkin.run(flexkin.parabola(links=4), [[0.1, 0.0]])
    target = tmp_path / "keep.json"
    target.write_text("old")
    frames = res.frames  # a writable view of the result's own frames
    assert frames.flags.writeable
    frames[0, 0, 0] = np.nan
    with pytest.raises(flexkin.InputError, match="frames"):
        res.write(target)
    assert target.read_text() == "old"
    with pytest.raises(flexkin.InputError) as info:
        res.write(tmp_path / "result.txt")
    assert ".npz" in str(info.value)


def test_validate_scenario():
    path = EXAMPLES / "fig10_planar_curve.json"
    assert flexkin.validate_scenario(path) == []
    with open(path) as f:
        scenario = json.load(f)
    assert flexkin.validate_scenario(scenario) == []
    scenario["options"] = {}
    scenario["method"] = "no_such_method"
    problems = flexkin.validate_scenario(scenario)
    assert problems and all(set(p) == {"field", "message", "value", "expected"} for p in problems)
    assert {p["field"] for p in problems} >= {"/options", "/method"}
    with pytest.raises(OSError):
        flexkin.validate_scenario(EXAMPLES / "no_such_scenario.json")


def test_estimate_output():
    e = flexkin.estimate_output(10, 2, 100, record_every=10)
    assert e["frames"] == 11 and e["link_angles"] is True
    assert e["npz_bytes"] < e["json_bytes"]
    assert flexkin.estimate_output(10, 2, 100, link_angles=False)["frames"] == 101
    with pytest.raises(flexkin.InputError):
        flexkin.estimate_output(10, 4, 100)


def test_result_arrays_are_views_of_the_dense_frames(tmp_path):
    # A run's frames, steps and link angles reach Python without a copy: every access is a view
    # of the same memory, owned by the Result; an edit through it is what write() writes.
    res = flexkin.run(flexkin.parabola(links=6), [[0.1, 0.0], [0.2, 0.05]])
    assert res.frames.base is res and res.steps.base is res and res.link_angles.base is res
    assert np.shares_memory(res.frames, res.frames)
    assert res.frames.__array_interface__["data"][0] == res.frames.__array_interface__["data"][0]
    res.frames[1, 2, 0] += 0.5
    res.write(tmp_path / "r.npz")
    back = flexkin.read_result(tmp_path / "r.npz")
    assert back.frames[1, 2, 0] == res.frames[1, 2, 0]
    # A result file read back is the same form: views of its dense arrays.
    assert back.frames.base is back and back.frames.flags.c_contiguous
    assert back.frames.shape == (3, 7, 2) and back.link_angles.shape == (3, 6)
    # The view keeps its Result alive.
    frames = flexkin.read_result(tmp_path / "r.npz").frames
    import gc
    gc.collect()
    assert np.array_equal(frames, back.frames)
    # Pickling copies the arrays out and back into a new Result's dense frames.
    import pickle
    again = pickle.loads(pickle.dumps(back))
    assert np.array_equal(again.frames, back.frames) and again.frames.base is again
    assert np.array_equal(again.link_angles, back.link_angles)
    assert again == back


def test_run_scenario_writes_result_and_csv_files(tmp_path):
    # run_scenario(output=, csv=) goes through the library's one call (RunToFiles), as
    # `flexkin run -o --csv` does; the Result keeps its frames.
    scenario = EXAMPLES / "fig10_planar_curve.json"
    res = flexkin.run_scenario(scenario, output=tmp_path / "py.npz", csv=tmp_path / "py.csv")
    back = flexkin.read_result(tmp_path / "py.npz")
    assert np.array_equal(back.frames, res.frames) and np.array_equal(back.steps, res.steps)
    assert back.scenario == res.scenario != ""
    assert (tmp_path / "py.csv").read_text().startswith("step,point,x,y\n")
    with pytest.raises(flexkin.InputError) as info:
        flexkin.run_scenario(scenario, output=tmp_path / "r.txt")
    assert info.value.field == "output"
    assert not (tmp_path / "r.txt").exists()


def test_run_scenario_files_equal_the_command_lines(cli, tmp_path):
    scenario = EXAMPLES / "fig10_planar_curve.json"
    res = flexkin.run_scenario(scenario, output=tmp_path / "py.npz", csv=tmp_path / "py.csv")
    subprocess.run([cli, "run", str(scenario), "-o", str(tmp_path / "cli.npz"), "--csv",
                    str(tmp_path / "cli.csv"), "-q"], check=True)
    assert (tmp_path / "cli.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
    assert np.array_equal(flexkin.read_result(tmp_path / "cli.npz").frames, res.frames)


def test_colliders_travel_with_the_result(tmp_path):
    # The rope round its post: run_scenario's Result, its files and a Result read back and written
    # again all carry the post, in the scenario's form (docs/result-format.md, "colliders").
    scenario = EXAMPLES / "rope_round_post.json"
    posts = json.loads(scenario.read_text())["colliders"]
    res = flexkin.run_scenario(scenario, output=tmp_path / "rope.npz")
    res.write(tmp_path / "memory.json")
    assert json.loads((tmp_path / "memory.json").read_text())["colliders"] == posts
    again = tmp_path / "again.json"
    flexkin.read_result(tmp_path / "rope.npz").write(again)
    assert json.loads(again.read_text())["colliders"] == posts
    # A result without colliders has no such key.
    plain = tmp_path / "plain.json"
    flexkin.run_scenario(EXAMPLES / "fig10_planar_curve.json").write(plain)
    assert "colliders" not in json.loads(plain.read_text())
