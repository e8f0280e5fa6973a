"""fit_circle on arcs generated here with numpy."""

import numpy as np
import pytest

import arcwheel


@pytest.mark.parametrize("center, radius, start_rad, arc_rad", [
    ((10.0, -3.0), 125.0, 0.3, 1.2),
    ((1e5, -2e4), 55.4423, 2.0, np.radians(10.0)),  # a short arc far from the origin
    ((0.0, 0.0), 0.5, 0.0, 2 * np.pi * 0.9),
])
def test_an_exact_arc_is_fitted_exactly(center, radius, start_rad, arc_rad):
    angle = start_rad + np.linspace(0.0, arc_rad, 50)
    points = np.column_stack([center[0] + radius * np.cos(angle), center[1] + radius * np.sin(angle)])
    fit = arcwheel.fit_circle(points)
    assert fit.usable, fit.message
    assert abs(fit.radius_mm - radius) < 1e-9
    assert np.all(np.abs(fit.center_mm - center) < 1e-9)
    assert fit.rms_residual_mm < 1e-9 and fit.n == 50
    assert fit.center_sigma_mm.shape == (2,) and fit.covariance.shape == (3, 3)


def test_the_sigmas_describe_the_spread_of_noisy_fits():
    rng = np.random.default_rng(7)
    angle = np.linspace(0.0, 1.0, 200)
    radii, sigmas = [], []
    for _ in range(200):
        noise = rng.normal(0.0, 0.002, angle.size)
        points = np.column_stack([(50 + noise) * np.cos(angle), (50 + noise) * np.sin(angle)])
        fit = arcwheel.fit_circle(points)
        radii.append(fit.radius_mm)
        sigmas.append(fit.radius_sigma_mm)
    # 200 draws: the spread's estimate is good to about 10 %.
    assert np.std(radii) == pytest.approx(np.mean(sigmas), rel=0.2)


def test_points_that_are_not_n_by_2_are_refused():
    with pytest.raises(arcwheel.InvalidOptionError, match=r"\(N, 2\)"):
        arcwheel.fit_circle(np.zeros((5, 3)))
    collinear = np.column_stack([np.arange(5.0), np.zeros(5)])
    assert not arcwheel.fit_circle(collinear).usable
