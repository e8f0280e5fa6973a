"""Errors raise arcwheel's exceptions, with the exit status, its meaning and the stage."""

import json

import pytest

import arcwheel


def test_a_file_that_is_not_hdf5_raises_bad_input_naming_the_file(tmp_path):
    bad = tmp_path / "not_a_scan.h5"
    bad.write_bytes(b"this is no HDF5 file\n" * 10)
    for call in (arcwheel.read_scan, arcwheel.process):
        with pytest.raises(arcwheel.BadInputError) as raised:
            call(bad)
        assert str(bad) in str(raised.value)
        assert raised.value.exit_code == 3 and raised.value.meaning == "bad input"
        assert raised.value.stage and str(raised.value).startswith(raised.value.stage + ": ")
        assert isinstance(raised.value, arcwheel.Error)


def test_a_csv_with_a_bad_line_names_the_file_and_line(tmp_path):
    bad = tmp_path / "scan.csv"
    bad.write_text("# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm\n0.1\nabc\n")
    with pytest.raises(arcwheel.BadInputError, match="scan.csv.*line 6|line 6.*scan.csv"):
        arcwheel.read_scan(bad)


def test_a_missing_file_is_an_io_error(tmp_path):
    with pytest.raises(arcwheel.Error) as raised:
        arcwheel.read_scan(tmp_path / "absent.h5")
    assert raised.value.exit_code in (3, 4) and "absent.h5" in str(raised.value)


def test_a_summary_without_a_contract_key_names_the_file_and_key(processed, tmp_path):
    summary = dict(processed.summary)
    del summary["mean_arc_radius_mm"]
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(summary))
    with pytest.raises(arcwheel.BadInputError, match="mean_arc_radius_mm") as raised:
        arcwheel.read_summary(path)
    assert str(path) in str(raised.value)


def test_bad_options_raise_invalid_option_naming_them(simulated):
    path, _, _ = simulated
    with pytest.raises(arcwheel.InvalidOptionError, match="'phasez'"):
        arcwheel.process(path, phasez=90)
    with pytest.raises(arcwheel.InvalidOptionError, match="'phases'.*2.5"):
        arcwheel.process(path, phases=2.5)
    with pytest.raises(arcwheel.InvalidOptionError, match="despike = sideways") as raised:
        arcwheel.process(path, despike="sideways", phases=2)
    assert "--phases = 2" in str(raised.value)  # every problem in one message
    assert raised.value.exit_code == 2 and raised.value.stage == "process"
    assert isinstance(raised.value, ValueError)
    with pytest.raises(arcwheel.InvalidOptionError, match="radius_harmonic"):
        arcwheel.simulate(radius_harmonic=["2"])


@pytest.mark.parametrize("status, cls", [(2, arcwheel.InvalidOptionError), (3, arcwheel.BadInputError),
                                         (4, arcwheel.IoError), (5, arcwheel.FitFailedError),
                                         (70, arcwheel.InternalError)])
def test_each_exit_status_has_its_exception(status, cls):
    with pytest.raises(cls) as raised:
        arcwheel._arcwheel._raise(status, "some.stage", "detail")
    assert raised.value.exit_code == status and raised.value.stage == "some.stage"
    assert str(raised.value) == "some.stage: detail"


def test_an_interrupted_stage_is_a_keyboard_interrupt():
    with pytest.raises(KeyboardInterrupt):
        arcwheel._arcwheel._raise(130, "arcwheel", "interrupted by a signal")
