"""arcwheel from Python: read scans, process them, simulate them, and read the results.

The stages are arcwheel's C++ libraries (the extension module arcwheel._arcwheel); arrays are
numpy arrays. See docs/python.md for the whole API.

    import arcwheel
    result = arcwheel.process("testdata/paper_wheel_scan.h5")
    result.fits["arc_radius_mm"]          # per-phase arc radius Ra(c), mm
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Optional, Union

# Imported here, before any call: the extension would otherwise import numpy the first time it
# returns an array, after the work, where a Ctrl-C that arrives then interrupts numpy's own
# import half way and leaves it broken for the rest of the session.
import numpy  # noqa: F401

from . import _arcwheel
from ._arcwheel import (
    PROCESS_OPTIONS,
    SIMULATE_OPTIONS,
    Scan,
    __version__,
    DEFAULT_MAX_WHEEL_CHANGE_MM,
    read_grid_map,
    read_scan,
    read_summary,
    read_wheel_map,
)

__all__ = [
    "Error", "InvalidOptionError", "BadInputError", "IoError", "FitFailedError", "InternalError",
    "Scan", "Result", "CircleFit", "read_scan", "process", "simulate", "fit_circle", "read_summary",
    "read_wheel_map", "PROCESS_OPTIONS", "SIMULATE_OPTIONS", "__version__",
    "toolpath", "polish", "compare", "history", "frame", "fit_transform", "headcenter", "read_grid_map",
]


class Error(Exception):
    """An arcwheel error. `exit_code` is the exit status `arcwheel` would end with, `meaning` its
    name ("bad input", ...), `stage` the stage id that raised it ("hdf5", "process", ...); the
    message names the file and key, line or dataset as the command line's does."""

    exit_code = 1
    meaning = "error"

    def __init__(self, message: str, stage: str = "", exit_code: Optional[int] = None,
                 meaning: Optional[str] = None):
        super().__init__(message)
        self.stage = stage
        if exit_code is not None:
            self.exit_code = exit_code
        if meaning is not None:
            self.meaning = meaning


class InvalidOptionError(Error, ValueError):
    """An option is unknown or out of range (exit status 2)."""
    exit_code, meaning = 2, "invalid option"


class BadInputError(Error):
    """An input file is malformed or cannot support the computation (exit status 3)."""
    exit_code, meaning = 3, "bad input"


class IoError(Error):
    """A file cannot be opened, read, written or renamed (exit status 4)."""
    exit_code, meaning = 4, "I/O error"


class FitFailedError(Error):
    """No usable result could be computed from otherwise valid input (exit status 5)."""
    exit_code, meaning = 5, "fit failed"


class InternalError(Error):
    """A broken invariant: a bug in arcwheel (exit status 70)."""
    exit_code, meaning = 70, "internal error"


# Ctrl-C (exit status 130) is KeyboardInterrupt.
_arcwheel._register_errors({cls.exit_code: cls for cls in
                            (InvalidOptionError, BadInputError, IoError, FitFailedError, InternalError)})


@dataclasses.dataclass
class Result:
    """What `arcwheel process` computes (docs/outputs.md).

    summary: dict, the content of summary.json.
    map:     wheel_map.h5's /map: phase_deg [n_phase], y_mm [n_y], rho (mm), form_error_um,
             sample_count and despiked_count (int32), each [n_phase, n_y].
    fits:    the per-phase arc fits, [n_phase]: phase_deg, arc_radius_mm, arc_radius_sigma_mm,
             center_axial_mm(+_sigma_mm), center_radial_mm(+_sigma_mm), arc_error_um, chi2_per_dof
             (NaN where a phase is not usable, as in wheel_map.h5's /fit), points_in_band (int32),
             usable (bool), flag (list of str, empty when usable).
    axial:   runout and roundness per axial node of the band: y_mm, runout_um, roundness_um.
    model:   wheel_map.h5's /model arrays (plus phase_deg), or None with no_model=True or when the
             model could not be fitted (summary["warnings"] says why).
    timings: [(stage, seconds)], as `arcwheel process --timings` prints them.
    """

    summary: dict
    map: dict
    fits: dict
    axial: dict
    model: Optional[dict]
    timings: list


def process(scan_or_path: Union[Scan, str, os.PathLike], output_dir: Union[str, os.PathLike, None] = None,
            *, report: bool = False, tolerances: Union[str, os.PathLike, None] = None,
            **options: Any) -> Result:
    """Runs `arcwheel process` on a scan file or a Scan (read_scan, simulate) and returns a Result.

    options are the command's, in snake_case (PROCESS_OPTIONS holds them with their defaults), e.g.
    phases=180, band_half_width_mm=6.0, despike="moving-mean", no_model=True, uncertainty="budget.json",
    no_uncertainty=True. With output_dir, the
    command's files (summary.json, wheel_map.h5) are written there too, and with report=True its
    HTML and PDF report (tolerances: a tolerance file, docs/reports.md).

    A Scan in memory has no file behind it: summary["input"]["sha256"] is empty then.
    Raises InvalidOptionError, BadInputError, IoError or FitFailedError; Ctrl-C raises
    KeyboardInterrupt (and leaves no partial output file).
    """
    if options.get("uncertainty") is not None:
        options["uncertainty"] = os.fspath(options["uncertainty"])
    parts = _arcwheel._process(scan_or_path, output_dir=_path_or_none(output_dir), report=report,
                               tolerances=_path_or_none(tolerances), **options)
    return Result(**parts)


def simulate(output: Union[str, os.PathLike, None] = None, *, truth: Union[str, os.PathLike, None] = None,
             **options: Any) -> tuple[Scan, dict]:
    """A synthetic helical scan of a wheel with known geometry, as `arcwheel simulate` makes it.

    Returns (scan, truth): the Scan (float32 readings unless float64=True, as the file stores them)
    and the truth as a dict (per-phase arc radius and centre under truth["phases"]). With `output`
    (.h5/.hdf5 or .csv/.txt), the scan file and its truth JSON (`truth`, default
    OUTPUT.truth.json) are written too. options are the command's, in snake_case
    (SIMULATE_OPTIONS); harmonics are lists of "ORDER:AMPLITUDE[:PHASE_DEG]" strings or
    (order, amplitude[, phase_deg]) tuples, e.g. radius_harmonic=[(2, 0.01)].
    """
    return _arcwheel._simulate(_path_or_none(output), truth=_path_or_none(truth), **options)


@dataclasses.dataclass
class CircleFit:
    """A geometric least-squares circle (fitting/circle_fit.h), with 1-sigma uncertainties."""

    center_mm: Any          # numpy array (2,)
    radius_mm: float
    center_sigma_mm: Any    # numpy array (2,)
    radius_sigma_mm: float
    covariance: Any         # numpy array (3, 3) of (a, b, r), mm^2
    rms_residual_mm: float
    pv_residual_mm: float
    chi2: float
    n: int
    iterations: int
    status: str             # "converged", "no_convergence" or "degenerate"
    message: str

    @property
    def usable(self) -> bool:
        return self.status == "converged"


def fit_circle(points, weights=None, *, max_iterations: int = 100,
               weights_are_inverse_sigmas: bool = False) -> CircleFit:
    """Fits a circle to an (N, 2) array of points (mm), N >= 3, started from the algebraic fit.

    weights: one per point (1 when None); with weights_are_inverse_sigmas the covariance is that
    of known noise, else it is scaled by the residual variance. A fit that does not converge is
    returned with its status (not raised)."""
    return CircleFit(**_arcwheel._fit_circle(points, weights, max_iterations, weights_are_inverse_sigmas))


def _read_table(path) -> dict:
    """A CSV table arcwheel wrote ('#' header lines, then a line of column names): {column: array}."""
    with open(path, encoding="utf-8") as table:
        lines = [line for line in table if line.strip() and not line.startswith("#")]
    names = [name.strip() for name in lines[0].split(",")]
    values = numpy.loadtxt(lines[1:], delimiter=",", dtype=float, ndmin=2).reshape(-1, len(names))
    return {name: values[:, i].copy() for i, name in enumerate(names)}


def _in_folder(output_dir, run):
    """Runs run(folder) in output_dir, or in a temporary folder removed afterwards."""
    if output_dir is not None:
        return run(os.fspath(output_dir))
    import tempfile
    with tempfile.TemporaryDirectory(prefix="arcwheel-") as folder:
        return run(folder)


def toolpath(job: Union[str, os.PathLike], wheel: Union[str, os.PathLike, None] = None,
             output_dir: Union[str, os.PathLike, None] = None, *,
             max_wheel_change_mm: float = DEFAULT_MAX_WHEEL_CHANGE_MM, wheel_profile: str = "mean") -> dict:
    """Runs `arcwheel toolpath JOB [--wheel SUMMARY]` (docs/grinding.md): the same library calls.

    wheel: a measured wheel's summary.json (arcwheel.process's output), which replaces the job's
    wheel; wheel_profile "mean" or "model" as --wheel-profile. The command's files go to output_dir
    (a temporary folder when None). Returns {"summary": toolpath_summary.json as a dict,
    "toolpath": {column: array} of toolpath.csv (xw_mm, yw_mm, zw_mm, x_mm, ..., row, pass),
    "prediction": prediction.h5 as read_grid_map gives it, or None without a prediction}.
    Raises InvalidOptionError, BadInputError (stage "grinding.job", ...) or IoError.
    """
    def run(folder):
        parts = _arcwheel._toolpath(os.fspath(job), _path_or_none(wheel), folder, max_wheel_change_mm,
                                    wheel_profile)
        parts["toolpath"] = _read_table(os.path.join(folder, "toolpath.csv"))
        prediction = os.path.join(folder, "prediction.h5")
        parts["prediction"] = read_grid_map(prediction) if os.path.exists(prediction) else None
        return parts
    return _in_folder(output_dir, run)


def polish(job: Union[str, os.PathLike], error_map: Union[str, os.PathLike, None] = None,
           output_dir: Union[str, os.PathLike, None] = None) -> dict:
    """Runs `arcwheel polish JOB` (docs/polishing.md), error_map replacing the job's error_map.file.

    The command's files go to output_dir (a temporary folder when None). Returns {"summary":
    polish_summary.json as a dict, "path": {column: array} of polishing_path.csv (the dwell points),
    "residual": {column: array} of residual_map.csv (x_mm, y_mm, target_um, removal_um,
    residual_um per aperture node), "residual_map": residual_map.h5 as read_grid_map gives it}.
    Raises InvalidOptionError, BadInputError (stage "polishing.job", ...) or IoError.
    """
    def run(folder):
        parts = _arcwheel._polish(os.fspath(job), _path_or_none(error_map), folder)
        parts["path"] = _read_table(os.path.join(folder, "polishing_path.csv"))
        parts["residual"] = _read_table(os.path.join(folder, "residual_map.csv"))
        grid = os.path.join(folder, "residual_map.h5")
        parts["residual_map"] = read_grid_map(grid) if os.path.exists(grid) else None
        return parts
    return _in_folder(output_dir, run)


def compare(before_dir: Union[str, os.PathLike], after_dir: Union[str, os.PathLike]) -> dict:
    """`arcwheel compare BEFORE_DIR AFTER_DIR` (docs/reports.md) without writing: {"comparison":
    what compare.json holds (headline changes with their combined sigma and significance),
    "map": {phase_deg [n_phase], y_mm [n_y], difference_um [n_phase, n_y]}}.
    Raises BadInputError (stage "reports.compare", ...) or IoError."""
    return _arcwheel._compare(os.fspath(before_dir), os.fspath(after_dir))


def history(folders=None, *, wheel: Optional[str] = None, since: Optional[str] = None,
            db: Optional[str] = None, dressings=()) -> dict:
    """`arcwheel history` (docs/reports.md) without writing: the scans of one wheel in time order,
    from `folders` (arcwheel process outputs) or, with wheel=ID, from the results store (db, else
    $ARCWHEEL_DB; since="YYYY-MM-DD" keeps the later scans). dressings: ISO 8601 date-times.

    Returns {"wheel_id", "timestamp": [str], "folder": [str], "time_s", "segment",
    "mean_arc_radius_mm", "mean_arc_radius_sigma_mm", "max_runout_um", "max_arc_error_um" (arrays,
    one entry per scan), "wear": [{segment, scans, rate_um_per_h, sigma_um_per_h, chi2_per_dof,
    intercept_mm, first_time_s, last_time_s}], "csv": history.csv's text}.
    Raises InvalidOptionError, BadInputError (stage "reports.history" or "store") or IoError."""
    paths = [os.fspath(f) for f in (folders or [])]
    return _arcwheel._history(paths, wheel or "", since or "", db or "", list(dressings))


def frame(p1, p2, p3, *, min_separation_mm: float = 1e-3, min_angle_deg: float = 0.1) -> dict:
    """`arcwheel frame` (docs/frames.md): the three-point workpiece frame from probed P1 (origin),
    P2 (on +X) and P3 (in the XY plane, +Y side), machine coordinates in mm. Returns {"origin_mm"
    (3,), "axes" (3, 3) (columns i, j, k), "angle_p2_p3_deg", "machine_from_workpiece" and
    "workpiece_from_machine" (4, 4), "transform": the transform JSON the command writes}.
    Raises BadInputError (stage "frames.three_point") for coincident or collinear points."""
    return _arcwheel._frame(list(map(float, p1)), list(map(float, p2)), list(map(float, p3)),
                            min_separation_mm, min_angle_deg)


def fit_transform(source, target, model: str = "rigid3d", *, outlier_threshold: float = 3.0,
                  drop_outliers: bool = False) -> dict:
    """`arcwheel transform fit` (docs/frames.md): the best-fit transform target = T(source) of
    (N, 3) (or (N, 2)) point arrays in mm; model as --model (rigid3d, similarity3d, rigid2d, ...).
    Returns {"fit": the JSON the command writes, "matrix" (4, 4), "parameters", "residuals_mm"
    (N, 3), "rms_residual_mm"}. Raises InvalidOptionError or BadInputError."""
    return _arcwheel._fit_transform(numpy.asarray(source, dtype=float), numpy.asarray(target, dtype=float),
                                    model, outlier_threshold, drop_outliers)


def headcenter(record: Union[str, os.PathLike], *, calibration: Union[str, os.PathLike, None] = None,
               commanded_mm=None, z0_mm: Optional[float] = None, tare: Union[str, os.PathLike, None] = None,
               min_force_fraction: float = 0.1, min_force_N: float = 0.0) -> dict:
    """`arcwheel headcenter solve RECORD` (docs/frames.md): the contact (removal) centre of one
    force/torque record. Returns {"result": the JSON the command writes, "centre_mm" (2,) and
    "centre_sigma_mm" (2,) in the sensor frame, "centre_machine_mm" and "offset_mm" ((2,) with a
    calibration, and commanded_mm for the offset; else None)}.
    Raises InvalidOptionError, BadInputError (stage "frames.force_record", ...) or IoError."""
    return _arcwheel._headcenter(os.fspath(record), _path_or_none(calibration) or "",
                                 None if commanded_mm is None else list(map(float, commanded_mm)),
                                 z0_mm, _path_or_none(tare) or "", min_force_fraction, min_force_N)


def _path_or_none(path):
    return None if path is None else os.fspath(path)
