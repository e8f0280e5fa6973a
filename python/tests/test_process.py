"""arcwheel.process against the simulator's truth, and the shapes and types of what it returns."""

import json

import numpy as np
import pytest

import arcwheel


def truth_at(truth, key, phase_deg):
    """The truth's per-phase `key` at the phase nodes `phase_deg` (the truth's nodes are 1 deg)."""
    nodes = np.asarray(truth["phases"]["phase_deg"])
    values = np.asarray(truth["phases"][key])
    index = np.searchsorted(nodes, phase_deg)
    assert np.allclose(nodes[index], phase_deg), "the map's phase nodes are truth nodes"
    return values[index]


def test_the_mean_arc_radius_matches_the_truth_within_3_sigma(simulated, processed):
    _, truth, _ = simulated
    s = processed.summary
    # The mean over the usable phases of the generating circles' radii.
    usable = processed.fits["usable"]
    expected = truth_at(truth, "arc_radius_mm", processed.fits["phase_deg"][usable]).mean()
    assert abs(s["mean_arc_radius_mm"] - expected) < 3 * s["mean_arc_radius_sigma_mm"]
    assert s["usable_phases"] == usable.sum() > 0.9 * len(usable)


def test_the_per_phase_fits_match_the_truth_within_3_sigma(simulated, processed):
    _, truth, _ = simulated
    f = processed.fits
    usable = f["usable"]
    phases = f["phase_deg"][usable]
    for key in ("arc_radius_mm", "center_axial_mm", "center_radial_mm"):
        z = (f[key][usable] - truth_at(truth, key, phases)) / f[key.replace("_mm", "_sigma_mm")][usable]
        # Gaussian errors: 0.27 % beyond 3 sigma; allow 2 % for the correlation between neighbours.
        assert np.mean(np.abs(z) > 3) < 0.02, (key, np.abs(z).max())
        assert np.abs(z).max() < 5, key


def test_the_wheel_model_matches_the_truth_within_3_sigma(simulated, processed):
    _, truth, _ = simulated
    m = processed.model
    assert m is not None
    expected = np.mean(truth["phases"]["arc_radius_mm"])  # the mean of Ra(c) over a turn
    model = processed.summary["model"]
    assert abs(model["mean_arc_radius_mm"] - expected) < 3 * model["mean_arc_radius_sigma_mm"]
    z = (m["arc_radius_mm"] - truth_at(truth, "arc_radius_mm", m["phase_deg"])) / m["arc_radius_sigma_mm"]
    assert np.abs(z).max() < 4


def test_a_scan_in_memory_gives_the_results_of_its_file(simulated, processed):
    _, _, scan = simulated
    in_memory = arcwheel.process(scan, phases=180)
    np.testing.assert_array_equal(in_memory.fits["arc_radius_mm"], processed.fits["arc_radius_mm"])
    assert in_memory.summary["input"]["sha256"] == ""
    assert len(processed.summary["input"]["sha256"]) == 64


def test_the_record_names_a_scan_that_no_file_holds():
    from conftest import WHEEL
    scan, _ = arcwheel.simulate(**WHEEL)
    result = arcwheel.process(scan, phases=90, no_model=True)
    assert result.summary["input"]["format"] == "memory"
    assert result.summary["input"]["sha256"] == ""


def test_the_arrays_are_numpy_arrays_of_the_map_shape(processed):
    m, f, a = processed.map, processed.fits, processed.axial
    n_phase, n_y = 180, len(m["y_mm"])
    assert n_y > 10
    assert m["phase_deg"].shape == (n_phase,)
    for key in ("rho", "form_error_um", "sample_count", "despiked_count"):
        assert isinstance(m[key], np.ndarray) and m[key].shape == (n_phase, n_y), key
    assert m["rho"].dtype == np.float64 and m["form_error_um"].dtype == np.float64
    assert m["sample_count"].dtype == np.int32 and m["despiked_count"].dtype == np.int32
    np.testing.assert_allclose(m["phase_deg"], np.arange(n_phase) * 2.0)
    assert np.all(np.diff(m["y_mm"]) > 0)
    for key in ("arc_radius_mm", "arc_radius_sigma_mm", "center_axial_mm", "center_radial_mm", "arc_error_um",
                "chi2_per_dof"):
        assert f[key].shape == (n_phase,) and f[key].dtype == np.float64, key
    assert f["usable"].dtype == np.bool_ and f["points_in_band"].dtype == np.int32
    assert len(f["flag"]) == n_phase
    assert a["y_mm"].shape == a["runout_um"].shape == a["roundness_um"].shape
    model = processed.model
    assert model["covariance"].shape == (len(model["coefficients"]),) * 2
    assert model["residual_um"].shape == (n_phase, n_y)
    # The summary is summary.json's document: plain JSON types.
    json.dumps(processed.summary)


def test_output_dir_writes_the_files_the_readers_read_back(simulated, processed, tmp_path):
    h5py = pytest.importorskip("h5py")
    path, _, _ = simulated
    result = arcwheel.process(path, tmp_path / "out", phases=180)
    summary = arcwheel.read_summary(tmp_path / "out" / "summary.json")
    assert summary["mean_arc_radius_mm"] == result.summary["mean_arc_radius_mm"]
    assert summary["input"]["sha256"] == result.summary["input"]["sha256"]
    wheel_map = arcwheel.read_wheel_map(tmp_path / "out" / "wheel_map.h5")
    with h5py.File(tmp_path / "out" / "wheel_map.h5", "r") as f:
        np.testing.assert_array_equal(wheel_map["map"]["rho"], f["/map/rho"][()])
        np.testing.assert_array_equal(wheel_map["fit"]["arc_radius_mm"], f["/fit/arc_radius_mm"][()])
        sha256 = f.attrs["input_sha256"]
        assert wheel_map["attributes"]["input_sha256"] == (sha256.decode() if isinstance(sha256, bytes) else sha256)
        assert wheel_map["attributes"]["phases"] == 180
    np.testing.assert_array_equal(wheel_map["map"]["rho"], result.map["rho"])
    np.testing.assert_array_equal(wheel_map["fit"]["usable"], result.fits["usable"])
    np.testing.assert_array_equal(wheel_map["model"]["arc_radius_mm"], result.model["arc_radius_mm"])


def test_options_change_the_computation(simulated):
    path, _, _ = simulated
    result = arcwheel.process(path, phases=90, band_half_width_mm=3.0, no_model=True)
    assert result.map["phase_deg"].shape == (90,)
    assert result.model is None and "model" not in result.summary
    assert result.summary["band_half_width_mm"] == 3.0
    assert set(arcwheel.PROCESS_OPTIONS) >= {"phases", "despike", "rpm_source", "no_model", "model_knots"}
    assert arcwheel.PROCESS_OPTIONS["phases"] == 360


def test_the_uncertainty_options_reach_the_pipeline(simulated, tmp_path):
    path, _, _ = simulated
    without = arcwheel.process(path, no_model=True, no_uncertainty=True)
    assert "uncertainty" not in without.summary
    assert arcwheel.PROCESS_OPTIONS["no_uncertainty"] is False
    assert arcwheel.PROCESS_OPTIONS["uncertainty"] == ""
    # A budget file is read before the scan: one that is not JSON is refused, naming the file.
    budget = tmp_path / "budget.json"
    budget.write_text("{ not json")
    with pytest.raises(arcwheel.InvalidOptionError, match="budget.json"):
        arcwheel.process(path, no_model=True, uncertainty=budget)
