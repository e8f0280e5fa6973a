"""arcwheel.toolpath, polish, compare, history, frame, fit_transform and headcenter, each against a
value it did not compute: a closed form, the simulator's truth, or what the `arcwheel` command
wrote for the same input, read back with json, numpy and h5py."""

import json
import math
import os
import pathlib
import subprocess

import h5py
import numpy as np
import pytest

import arcwheel

SOURCE = pathlib.Path(__file__).resolve().parents[2]
BINARY = os.environ.get("ARCWHEEL_BINARY", str(SOURCE / "build" / "cli" / "arcwheel"))
# A quick scan (a fast feed) of the trial part's nominal wheel (55.4423 mm, 20 mm wide), so that
# --wheel is accepted and the measured profile covers the arc the toolpath uses.
SHORT = dict(noise_um=0.5, feed_mm_per_min=400.0)


def arcwheel_cli(*arguments):
    result = subprocess.run([BINARY, *map(str, arguments)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout


def read_csv(path):
    """A CSV table arcwheel wrote, read here: '#' lines skipped, then a header line."""
    lines = [line for line in pathlib.Path(path).read_text().splitlines() if line and not line.startswith("#")]
    names = lines[0].split(",")
    values = np.array([[float(cell) for cell in line.split(",")] for line in lines[1:]])
    return {name: values[:, i] for i, name in enumerate(names)}


def trial_sag_mm(x_mm, y_mm):
    """The trial part (even asphere R0 4066.172723 mm, k -0.581986, 300/300 mm off axis), from
    method.md A.9, not from arcwheel's surfaces."""
    c, k = 1.0 / 4066.172723, -0.581986
    sag = lambda r: c * r * r / (1.0 + np.sqrt(1.0 - (1.0 + k) * c * c * r * r))
    return sag(np.hypot(x_mm + 300.0, y_mm + 300.0)) - sag(math.hypot(300.0, 300.0))


@pytest.fixture(scope="module")
def grinding(tmp_path_factory):
    """A measured wheel (process output), the small trial-part job, and the CLI's toolpath of both."""
    work = tmp_path_factory.mktemp("grinding")
    arcwheel.simulate(work / "wheel.h5", seed=5, **SHORT)
    arcwheel.process(work / "wheel.h5", work / "wheel", phases=90, no_model=True)
    job = json.loads((SOURCE / "grinding" / "examples" / "trial_part.json").read_text())
    job["path"].update(step_over_mm=10.0, point_spacing_mm=10.0)
    job["gouge_check"] = {"spacing_mm": 50.0, "samples": 9}
    job["prediction"]["map_nodes"] = [44, 44]
    (work / "part.json").write_text(json.dumps(job))
    arcwheel_cli("toolpath", work / "part.json", "--wheel", work / "wheel" / "summary.json", "-o", work / "cli")
    return work


def test_toolpath_returns_what_the_command_writes_with_contact_points_on_the_surface(grinding):
    wheel = grinding / "wheel" / "summary.json"
    result = arcwheel.toolpath(grinding / "part.json", wheel=wheel)
    cli = read_csv(grinding / "cli" / "toolpath.csv")
    assert sorted(result["toolpath"]) == sorted(cli)
    for column, values in cli.items():
        np.testing.assert_array_equal(result["toolpath"][column], values, err_msg=column)
    # The contact points lie on the asphere (closed form).
    t = result["toolpath"]
    np.testing.assert_allclose(t["z_mm"], trial_sag_mm(t["x_mm"], t["y_mm"]), atol=1e-9)
    # The measured arc radius is the wheel's summary.json one.
    measured = json.loads(wheel.read_text())
    assert result["summary"]["arc_radius"]["measured_mm"] == measured["mean_arc_radius_mm"]
    assert result["summary"]["toolpath"]["control_points"] == len(t["x_mm"])
    with h5py.File(grinding / "cli" / "prediction.h5", "r") as f:
        np.testing.assert_array_equal(result["prediction"]["error_um"], f["error_um"][()])
        np.testing.assert_array_equal(result["prediction"]["x_mm"], f["x_mm"][()])


def test_toolpath_errors_name_the_stage(grinding, tmp_path):
    with pytest.raises(arcwheel.IoError) as error:
        arcwheel.toolpath(tmp_path / "no_job.json")
    assert error.value.stage.startswith("grinding") or "no_job.json" in str(error.value)
    with pytest.raises(arcwheel.InvalidOptionError) as error:
        arcwheel.toolpath(grinding / "part.json", wheel_profile="median")
    assert error.value.stage == "toolpath"
    assert not list(tmp_path.iterdir())


@pytest.fixture(scope="module")
def polishing(grinding):
    """A polishing job for the trial part whose error map is the toolpath's prediction, and the CLI's
    polish of it."""
    part = json.loads((grinding / "part.json").read_text())
    job = {"name": "trial part after grinding", "surface": part["surface"], "aperture": part["aperture"],
           "error_map": {"file": str(grinding / "cli" / "prediction.h5")},
           "removal_target": {"uniform_layer_um": 0.2},
           "removal_function": {"peak_rate_um_per_s": 0.1, "fwhm_mm": 60.0},
           "path": {"line_spacing_mm": 10.0, "point_spacing_mm": 10.0, "extension_mm": 40.0},
           "machine": {"max_speed_mm_s": 500.0}}
    (grinding / "polish.json").write_text(json.dumps(job))
    arcwheel_cli("polish", grinding / "polish.json", "-o", grinding / "polished")
    return grinding


def test_polish_returns_what_the_command_writes(polishing):
    result = arcwheel.polish(polishing / "polish.json")
    cli_summary = json.loads((polishing / "polished" / "polish_summary.json").read_text())
    for key in ("points", "total_time_s", "before", "after", "aperture_nodes"):
        assert result["summary"][key] == cli_summary[key], key
    for name, table in (("polishing_path.csv", result["path"]), ("residual_map.csv", result["residual"])):
        cli = read_csv(polishing / "polished" / name)
        for column, values in cli.items():
            np.testing.assert_array_equal(table[column], values, err_msg=f"{name} {column}")
    r = result["residual"]
    assert len(next(iter(result["path"].values()))) == cli_summary["points"]
    # The residual is what the target leaves after the removal, node by node.
    np.testing.assert_allclose(r["residual_um"], r["target_um"] - r["removal_um"], atol=1e-9)
    # The error map polished is the prediction file, read with h5py: the target is it plus the
    # uniform layer wherever the map has a value.
    with h5py.File(polishing / "cli" / "prediction.h5", "r") as f:
        error = f["error_um"][()]
        x0, dx, y0, dy = (f.attrs[k] for k in ("x0_mm", "dx_mm", "y0_mm", "dy_mm"))
    i = np.rint((r["x_mm"] - x0) / dx).astype(int)
    j = np.rint((r["y_mm"] - y0) / dy).astype(int)
    on_nodes = np.isclose(x0 + i * dx, r["x_mm"]) & np.isclose(y0 + j * dy, r["y_mm"])
    assert on_nodes.all()
    excess = r["target_um"] - error[j, i]
    assert np.ptp(excess) < 1e-6 and excess.min() >= 0.2 - 1e-9, (excess.min(), excess.max())


def test_polish_errors_name_the_stage(tmp_path):
    (tmp_path / "bad.json").write_text(json.dumps({"name": "no surface"}))
    with pytest.raises(arcwheel.BadInputError) as error:
        arcwheel.polish(tmp_path / "bad.json", output_dir=tmp_path / "out")
    assert error.value.stage.startswith("polishing"), error.value.stage
    assert not (tmp_path / "out").exists()


@pytest.fixture(scope="module")
def wear(tmp_path_factory):
    """Four scans of wheel H1 an hour apart whose arc radius shrinks by 1 um an hour, each processed
    by the command and recorded in a SQLite store."""
    work = tmp_path_factory.mktemp("wear")
    folders = []
    for i in range(4):
        scan = work / f"scan_{i}.h5"
        arcwheel.simulate(scan, seed=20 + i, arc_radius_mm=55.0 - 0.001 * i, wheel_id="H1",
                          timestamp=f"2026-03-01T{8 + i:02d}:00:00Z", **SHORT)
        arcwheel_cli("process", scan, "-o", work / f"out_{i}", "--phases", "90", "--no-model",
                     "--db", work / "results.sqlite")
        folders.append(work / f"out_{i}")
    return work, folders


def test_history_fits_the_simulated_wear_and_reads_the_same_from_the_store(wear):
    work, folders = wear
    h = arcwheel.history(folders)
    summaries = [json.loads((f / "summary.json").read_text()) for f in folders]
    radius = np.array([s["mean_arc_radius_mm"] for s in summaries])
    sigma = np.array([s["mean_arc_radius_sigma_mm"] for s in summaries])
    np.testing.assert_array_equal(h["mean_arc_radius_mm"], radius)
    # The weighted least-squares slope, written out here: radius against hours.
    t = np.arange(4.0)
    w = 1 / sigma**2
    tw = np.sum(w * t) / np.sum(w)
    slope_um_per_h = 1e3 * np.sum(w * (t - tw) * radius) / np.sum(w * (t - tw) ** 2)
    (rate,) = h["wear"]
    assert rate["rate_um_per_h"] == pytest.approx(slope_um_per_h, rel=1e-9)
    # The simulator's truth: -1 um/h.
    assert abs(rate["rate_um_per_h"] + 1.0) < 3 * rate["sigma_um_per_h"] + 0.05, rate
    stored = arcwheel.history(wheel="H1", db=str(work / "results.sqlite"))
    absolute = arcwheel.history([f.resolve() for f in folders])
    assert stored["csv"] == absolute["csv"]
    later = arcwheel.history(wheel="H1", db=str(work / "results.sqlite"), since="2026-03-01T10:00:00Z")
    assert later["timestamp"] == ["2026-03-01T10:00:00Z", "2026-03-01T11:00:00Z"]


def test_history_errors_name_the_stage(wear):
    work, _ = wear
    with pytest.raises(arcwheel.InvalidOptionError) as error:
        arcwheel.history()
    assert error.value.stage == "reports.history"
    with pytest.raises(arcwheel.BadInputError) as error:
        arcwheel.history(wheel="nope", db=str(work / "results.sqlite"))
    assert error.value.stage == "store"


def test_compare_reports_the_simulated_change_with_its_sigma(wear):
    _, folders = wear
    result = arcwheel.compare(folders[0], folders[3])
    before = json.loads((folders[0] / "summary.json").read_text())
    after = json.loads((folders[3] / "summary.json").read_text())
    changes = {c["key"]: c for c in result["comparison"]["changes"]}
    radius = changes["mean_arc_radius_mm"]
    assert radius["change"] == pytest.approx(after["mean_arc_radius_mm"] - before["mean_arc_radius_mm"], abs=1e-15)
    assert radius["sigma"] == pytest.approx(math.hypot(before["mean_arc_radius_sigma_mm"],
                                                       after["mean_arc_radius_sigma_mm"]), rel=1e-12)
    # The truth: 3 um smaller.
    assert abs(radius["change"] + 0.003) < 3 * radius["sigma"] + 2e-4
    with h5py.File(folders[0] / "wheel_map.h5", "r") as f:
        np.testing.assert_array_equal(result["map"]["phase_deg"], f["map/phase_deg"][()])
    assert result["map"]["difference_um"].shape == (len(result["map"]["phase_deg"]), len(result["map"]["y_mm"]))


def test_frame_of_three_probed_points_is_the_rotation_they_span():
    angle = math.radians(30.0)
    p1 = np.array([10.0, -4.0, 2.5])
    i = np.array([math.cos(angle), math.sin(angle), 0.0])
    j = np.array([-math.sin(angle), math.cos(angle), 0.0])
    result = arcwheel.frame(p1, p1 + 50 * i, p1 + 20 * j + 7 * i)
    np.testing.assert_allclose(result["axes"], np.column_stack([i, j, np.cross(i, j)]), atol=1e-12)
    np.testing.assert_allclose(result["origin_mm"], p1)
    point = np.array([3.0, 4.0, 5.0, 1.0])
    np.testing.assert_allclose(result["machine_from_workpiece"] @ point, np.append(p1 + 3 * i + 4 * j + 5 * np.cross(i, j), 1),
                               atol=1e-12)
    np.testing.assert_allclose(result["workpiece_from_machine"] @ result["machine_from_workpiece"], np.eye(4), atol=1e-12)
    with pytest.raises(arcwheel.BadInputError) as error:
        arcwheel.frame(p1, p1 + i, p1 + 2 * i)
    assert error.value.stage == "frames.three_point"


def test_fit_transform_recovers_a_known_rigid_motion():
    rng = np.random.default_rng(7)
    source = rng.uniform(-100, 100, size=(8, 3))
    rx, ry, rz = 0.1, -0.2, 0.3
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    rotation = (np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
                @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]))
    translation = np.array([5.0, -3.0, 12.0])
    target = source @ rotation.T + translation
    result = arcwheel.fit_transform(source, target, "rigid3d")
    np.testing.assert_allclose(result["matrix"][:3, :3], rotation, atol=1e-9)
    np.testing.assert_allclose(result["matrix"][:3, 3], translation, atol=1e-7)
    assert result["rms_residual_mm"] < 1e-9
    with pytest.raises(arcwheel.InvalidOptionError):
        arcwheel.fit_transform(source, target[:5])


def test_headcenter_finds_the_simulated_contact_centre_as_the_command_does(tmp_path):
    record, tare = tmp_path / "press.csv", tmp_path / "unloaded.csv"
    arcwheel_cli("headcenter", "simulate", "-o", record, "--centre-mm", "12.5,-7", "--seed", "3")
    arcwheel_cli("headcenter", "simulate", "-o", tare, "--unloaded", "--seed", "4")
    result = arcwheel.headcenter(record, tare=tare)
    centre, sigma = result["centre_mm"], result["centre_sigma_mm"]
    assert np.all(np.abs(centre - [12.5, -7.0]) < 4 * sigma + 0.05), (centre, sigma)
    cli = json.loads(arcwheel_cli("headcenter", "solve", record, "--tare", tare))
    assert result["result"] == cli
    with pytest.raises(arcwheel.IoError) as error:
        arcwheel.headcenter(tmp_path / "missing.csv")
    assert error.value.stage
