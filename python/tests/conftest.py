"""Shared fixtures: small simulated scans (a few 1e4 samples), so that the whole run takes seconds."""

import pytest

import arcwheel

# A wheel whose arc radius varies with the phase and whose centre wobbles axially, scanned
# with white noise; short (a 12 mm axial span) so that processing takes a fraction of a second.
WHEEL = dict(radius_harmonic=[(2, 0.004, 30.0)], axial_harmonic=["3:0.002"], radial_harmonic=[(1, 3.0)],
             noise_um=1.0, start_y_mm=-6.0, end_y_mm=6.0, width_mm=10.0, arc_radius_mm=40.0,
             seed=11)


@pytest.fixture(scope="session")
def simulated(tmp_path_factory):
    """(path of the .h5 scan, its truth dict, the Scan as simulate returned it)."""
    path = tmp_path_factory.mktemp("scan") / "wheel.h5"
    scan, truth = arcwheel.simulate(path, **WHEEL)
    return path, truth, scan


@pytest.fixture(scope="session")
def processed(simulated):
    """The Result of processing the simulated scan file at 180 phases."""
    path, _, _ = simulated
    return arcwheel.process(path, phases=180)
