"""Grooms from Python (docs/strands.md, docs/groom-format.md): run_groom writes the strand file
`flexkin run` writes, bit for bit; numpy reads it; lengths are kept; the overrides, a dict form,
progress and its interruption work; bad grooms and arguments are refused naming the field."""
import json
import subprocess

import numpy as np
import pytest

import flexkin
from conftest import EXAMPLES

SMALL = {
    "name": "small head",
    "groom": {"scalp": {"shape": "sphere", "center": [0, 0, 0], "radius": 0.1}, "roots": 300,
              "links": 10, "link_length": 0.008, "direction": {"droop": 0.5}, "seed": 5},
    "motion": {"fps": 30, "keyframes": [
        {"time": 0},
        {"time": 0.5, "rotation": {"axis": [0, 0, 1], "angle_deg": 45}},
        {"time": 1.0, "rotation": {"axis": [0, 1, 0], "angle_deg": 20},
         "translation": [0.01, 0, 0]}]},
    "record": {"every": 2, "precision": "float64"},
}


def members(path):
    with np.load(path) as z:
        return {name: z[name] for name in z.files}


def test_run_groom_reads_back_with_numpy(tmp_path):
    out = tmp_path / "hair.npz"
    report = flexkin.run_groom(SMALL, out, threads=2)
    assert isinstance(report, flexkin.StrandRunReport)
    assert report.threads == 2 and report.engine in ("avx512", "avx2", "scalar")
    assert 0 <= report.max_length_error < 1e-13
    z = members(out)
    info = json.loads(z["groom.json"])
    points, offsets = z["points"], z["offsets"]
    assert points.dtype == np.float64 and points.shape == (16, 300 * 11, 3)
    assert offsets.tolist() == list(range(0, 300 * 11 + 1, 11))
    assert z["frames"].tolist() == list(range(0, 31, 2))
    assert info["name"] == "small head" and info["num_strands"] == 300
    assert info["report"]["threads"] == 2
    # Every link keeps its length, from numpy alone.
    strands = points.reshape(16, 300, 11, 3)
    lengths = np.linalg.norm(np.diff(strands, axis=2), axis=3)
    rest = z["link_lengths"].reshape(300, 10)
    assert np.max(np.abs(lengths - rest) / rest) == pytest.approx(report.max_length_error, abs=0)
    # The roots ride rigidly on the body.
    roots_body = np.einsum("fji,fj->fi", z["body_rotation"],
                           strands[:, :, 0, :].transpose(1, 0, 2)[0] - z["body_translation"])
    assert np.allclose(np.linalg.norm(roots_body, axis=1), 0.1, atol=1e-15)


def test_same_file_as_the_command_line(tmp_path, cli):
    scenario = tmp_path / "g.json"
    scenario.write_text(json.dumps(SMALL))
    subprocess.run([cli, "run", str(scenario), "-o", str(tmp_path / "cli.npz"), "-q",
                    "--threads", "1"], check=True)
    flexkin.run_groom(scenario, tmp_path / "py.npz", threads=1)
    a, b = members(tmp_path / "cli.npz"), members(tmp_path / "py.npz")
    assert set(a) == set(b)
    for name in a:
        if name == "groom.json":
            ja, jb = json.loads(a[name]), json.loads(b[name])
            ja["report"].pop("seconds"), jb["report"].pop("seconds")
            assert ja == jb
        else:
            assert a[name].tobytes() == b[name].tobytes(), name


def test_overrides_and_example(tmp_path):
    out = tmp_path / "h.npz"
    flexkin.run_groom(SMALL, out, method="ftl", substeps=3, pinned=2, record_every=30,
                      precision="float32")
    z = members(out)
    info = json.loads(z["groom.json"])
    assert (info["method"], info["substeps"], info["pinned"]) == ("ftl", 3, 2)
    assert z["points"].dtype == np.float32 and z["frames"].tolist() == [0, 30]
    summary = flexkin.groom_summary(EXAMPLES / "groom_head.json")
    assert "5000 strands of 24 links" in summary
    assert flexkin.validate_scenario(EXAMPLES / "groom_head.json") == []


def test_progress_and_interruption(tmp_path):
    seen = []
    flexkin.run_groom(SMALL, tmp_path / "a.npz", progress=lambda done, total: seen.append(
        (done, total)))
    assert seen and seen[-1] == (31, 31)

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    (tmp_path / "b.npz").write_bytes(b"earlier")
    with pytest.raises(Stop):
        flexkin.run_groom(SMALL, tmp_path / "b.npz", progress=stop)
    assert (tmp_path / "b.npz").read_bytes() == b"earlier"


@pytest.mark.parametrize("change, field", [
    (lambda s: s["groom"].update(roots=0), "/groom/roots"),
    (lambda s: s["groom"]["scalp"].update(radius=-1), "/groom/scalp/radius"),
    (lambda s: s["motion"]["keyframes"][1].update(time=0), "/motion/keyframes/1/time"),
    (lambda s: s.update(method="overall"), "/method"),
])
def test_bad_grooms_name_the_field(tmp_path, change, field):
    scenario = json.loads(json.dumps(SMALL))
    change(scenario)
    with pytest.raises(flexkin.InputError) as e:
        flexkin.run_groom(scenario, tmp_path / "h.npz")
    assert field in str(e.value)
    assert [p for p in flexkin.validate_scenario(scenario) if field in p["field"]]
    assert not (tmp_path / "h.npz").exists()


@pytest.mark.parametrize("kwargs, name", [
    ({"method": "min_rotation"}, "method"), ({"substeps": 0}, "substeps"),
    ({"threads": -1}, "threads"), ({"record_every": 0}, "record_every"),
    ({"precision": "half"}, "precision"), ({"pinned": 0}, "pinned"),
])
def test_bad_arguments_name_the_argument(tmp_path, kwargs, name):
    with pytest.raises(flexkin.InputError) as e:
        flexkin.run_groom(SMALL, tmp_path / "h.npz", **kwargs)
    assert name in str(e.value)
    assert not (tmp_path / "h.npz").exists()


def test_files_that_cannot_be_read_or_written(tmp_path):
    with pytest.raises(FileNotFoundError):
        flexkin.run_groom(tmp_path / "missing.json", tmp_path / "h.npz")
    with pytest.raises(OSError):
        flexkin.run_groom(SMALL, tmp_path / "no" / "h.npz")
    with pytest.raises(flexkin.InputError):
        flexkin.run_groom(42, tmp_path / "h.npz")


def test_hair_numpy_example(tmp_path):
    """examples/python/hair_numpy.py (run by make demo) reads a strand file with numpy alone:
    the tips travel less than the roots and less than if rigid with the head."""
    import sys
    from conftest import SOURCE_DIR
    scenario = json.loads(json.dumps(SMALL))
    scenario["motion"]["keyframes"][2].pop("translation")
    flexkin.run_groom(scenario, tmp_path / "h.npz")
    out = subprocess.run([sys.executable, str(SOURCE_DIR / "examples/python/hair_numpy.py"),
                          str(tmp_path / "h.npz")], check=True, capture_output=True,
                         text=True, env={"PYTHONPATH": ""}).stdout
    rows = {line[:29].strip(): [float(v) for v in line[29:].split()]
            for line in out.splitlines()[1:4]}
    travelled = rows["mean path travelled (m)"]
    rigid = rows["as if rigid with the head (m)"]
    assert travelled[0] == rigid[0] > 0
    assert all(a >= b for a, b in zip(travelled, travelled[1:]))
    assert travelled[-1] < 0.8 * rigid[-1]
    assert "in the file's float64 coordinates" in out
