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
    read_scan,
    read_summary,
    read_wheel_map,
)

__all__ = [
    "Error", "InvalidOptionError", "BadInputError", "IoError", "FitFailedError", "InternalError",
    "Scan", "Result", "CircleFit", "read_scan", "process", "simulate", "fit_circle", "read_summary",
    "read_wheel_map", "PROCESS_OPTIONS", "SIMULATE_OPTIONS", "__version__",
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
    phases=180, band_half_width_mm=6.0, despike="moving-mean", no_model=True. With output_dir, the
    command's files (summary.json, wheel_map.h5) are written there too, and with report=True its
    HTML and PDF report (tolerances: a tolerance file, docs/reports.md).

    A Scan in memory has no file behind it: summary["input"]["sha256"] is empty then.
    Raises InvalidOptionError, BadInputError, IoError or FitFailedError; Ctrl-C raises
    KeyboardInterrupt (and leaves no partial output file).
    """
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


def _path_or_none(path):
    return None if path is None else os.fspath(path)
