"""read_scan on files other tools wrote, and simulate's scans."""

import numpy as np
import pytest

import arcwheel

h5py = pytest.importorskip("h5py")

RPM, FEED_MM_PER_MIN, PERIOD_S = 600.0, 120.0, 2e-4


def write_h5py_scan(path, z, **datasets):
    with h5py.File(path, "w") as f:
        g = f.create_group("scan")
        g.create_dataset("z", data=z)
        for name, values in datasets.items():
            g.create_dataset(name, data=values)
        g.attrs["spindle_rpm"] = RPM
        g.attrs["feed_mm_per_min"] = FEED_MM_PER_MIN
        g.attrs["sample_period_s"] = PERIOD_S
        g.attrs["invalid_value"] = np.float32(-999.0)
        g.attrs["wheel_id"] = "W-h5py"
        g.attrs["start_y_mm"] = -4.5


def test_a_scan_written_by_h5py_reads_back_the_same_numbers(tmp_path):
    rng = np.random.default_rng(20261202)
    n = 40000  # 8 s: 80 turns, 16 mm, far beyond the 2 turns and 3 pitches a scan needs
    z = rng.normal(0.0, 0.2, n).astype(np.float32)
    z[[5, 17, 1000]] = -999.0  # the file's invalid_value
    t = np.arange(n) * PERIOD_S
    angle = np.mod(t * RPM * 6.0, 360.0)
    path = tmp_path / "h5py_scan.h5"
    write_h5py_scan(path, z, t=t, angle=angle)

    scan = arcwheel.read_scan(path)
    assert len(scan) == n and scan.path == str(path)
    assert scan.z_mm.dtype == np.float32 and scan.z_mm.shape == (n,)
    expected = z.copy()
    expected[[5, 17, 1000]] = np.nan
    np.testing.assert_array_equal(scan.z_mm, expected)
    assert scan.valid_count() == n - 3
    assert scan.time_s.dtype == np.float64
    np.testing.assert_array_equal(scan.time_s, t)
    np.testing.assert_array_equal(scan.angle_deg, angle)
    assert scan.y_mm is None and scan.has_encoder
    m = scan.metadata
    assert (m["spindle_rpm"], m["feed_mm_per_min"], m["sample_period_s"]) == (RPM, FEED_MM_PER_MIN, PERIOD_S)
    assert m["invalid_value"] == -999.0 and m["wheel_id"] == "W-h5py" and m["start_y_mm"] == -4.5
    assert m["wheel_diameter_mm"] is None and m["radius_sign"] == 1.0

    wide = arcwheel.read_scan(path, keep_float32=False)
    assert wide.z_mm.dtype == np.float64
    np.testing.assert_array_equal(wide.z_mm, expected.astype(np.float64))
    with pytest.raises(ValueError):
        scan.z_mm[0] = 1.0  # a view of the scan's memory, read-only


def test_simulate_writes_the_file_it_returns(tmp_path):
    path = tmp_path / "sim.h5"
    scan, truth = arcwheel.simulate(path, end_y_mm=-5.0, time_column=True, wheel_id="W9")
    assert (tmp_path / "sim.h5.truth.json").exists()
    assert truth["counts"]["samples"] == len(scan) and truth["settings"]["spindle_rpm_nominal"] == 500.0
    assert len(truth["phases"]["arc_radius_mm"]) == 360
    again = arcwheel.read_scan(path)
    assert scan.z_mm.dtype == again.z_mm.dtype == np.float32
    np.testing.assert_array_equal(scan.z_mm, again.z_mm)
    np.testing.assert_array_equal(scan.time_s, again.time_s)
    assert again.metadata["wheel_id"] == "W9"
    # The time column as set: one sample period apart.
    np.testing.assert_allclose(np.diff(again.time_s), 100e-6, rtol=1e-9)

    scan64, _ = arcwheel.simulate(end_y_mm=-5.0, float64=True)
    assert scan64.z_mm.dtype == np.float64 and scan64.time_s is None and scan64.path == "simulated"
    assert arcwheel.SIMULATE_OPTIONS["rpm"] == 500.0
