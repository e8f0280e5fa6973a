#!/usr/bin/python3
"""Writes one scan's samples in the ways other tools write them: h5py and pandas (Debian's
python3-h5py and python3-pandas), for tests/foreign_files_test.cc.

    write_scans.py BASE.h5 OUTDIR

BASE.h5 is a plain scan (float z in /scan/z, numeric attributes on /scan). Every file in OUTDIR/good
holds exactly BASE's samples and numbers, and the text metadata of TEXT below; OUTDIR/bad holds files
that must be refused, and OUTDIR/expected.json says what each file's reader must give.
"""

import csv
import json
import os
import sys

import h5py
import numpy as np
import pandas as pd

# Text metadata as a user's script would set it: non-ASCII on purpose, and long enough that a
# reader which drops the last character of a fixed-length string shows it.
TEXT = {
    "wheel_id": "SYN-ARC-3fa19e",
    "sensor": "Keyence LK-H008 \u00b5m",
    "operator": "Zo\u00eb M\u00fcller \u5f20\u4f1f",
    "timestamp": "2017-09-13T10:00:00+08:00",
}
ASCII_TEXT = {key: value.encode("ascii", "replace").decode() for key, value in TEXT.items()}
ASCII_TEXT["sensor"] = "Keyence LK-H008"
ASCII_TEXT["operator"] = "Zoe Muller"


def read_base(path):
    with h5py.File(path, "r") as f:
        scan = f["scan"]
        columns = {name: scan[name][()] for name in ("z", "t", "angle", "y") if name in scan}
        numbers = {key: float(value) for key, value in scan.attrs.items() if np.asarray(value).dtype.kind in "fiu"}
    return columns, numbers


def write_h5(path, columns, numbers, text, *, z=None, text_writer=None, number_writer=None, dataset_options=None,
             file_options=None, z_attrs=None):
    with h5py.File(path, "w", **(file_options or {})) as f:
        scan = f.create_group("scan")
        for name, values in columns.items():
            data = z if (name == "z" and z is not None) else values
            options = dict(dataset_options or {})
            scan.create_dataset(name, data=data, **options)
        for key, value in numbers.items():
            (number_writer or default_number)(scan, key, value)
        for key, value in text.items():
            (text_writer or default_text)(scan, key, value)
        for key, value in (z_attrs or {}).items():
            scan["z"].attrs[key] = value


def default_number(scan, key, value):
    # h5py's defaults: a Python int is int64, a float is float64.
    scan.attrs[key] = int(value) if value == int(value) and key == "radius_sign" else value


def default_text(scan, key, value):
    scan.attrs[key] = value  # variable-length UTF-8


def low_level_text(padding, extra=0, charset=h5py.h5t.CSET_ASCII):
    """A fixed-length string attribute with the given padding, written through h5py's h5t/h5a."""

    def writer(scan, key, value):
        raw = value.encode("utf-8")
        size = len(raw) + extra
        string_type = h5py.h5t.C_S1.copy()
        string_type.set_size(size)
        string_type.set_strpad(padding)
        string_type.set_cset(charset)
        fill = b" " if padding == h5py.h5t.STR_SPACEPAD else b"\0"
        space = h5py.h5s.create(h5py.h5s.SCALAR)
        attribute = h5py.h5a.create(scan.id, key.encode(), string_type, space)
        attribute.write(np.array(raw + fill * extra, dtype=f"S{size}"), mtype=string_type)

    return writer


def fixed_ascii(scan, key, value):
    scan.attrs[key] = np.bytes_(value.encode("ascii"))  # h5py: fixed length, null-padded, ASCII


def fixed_utf8(scan, key, value):
    raw = value.encode("utf-8")
    scan.attrs.create(key, raw, dtype=h5py.string_dtype("utf-8", len(raw)))


def array_of_one_text(scan, key, value):
    scan.attrs.create(key, [value], dtype=h5py.string_dtype("utf-8"))


def array_of_one_number(scan, key, value):
    scan.attrs[key] = np.array([value])


def narrow_number(scan, key, value):
    """The narrowest type that holds the value exactly, big-endian where it is a float."""
    if value == int(value) and -128 <= value <= 127:
        scan.attrs.create(key, int(value), dtype=np.int8)
    elif value == int(value) and 0 <= value <= 65535:
        scan.attrs.create(key, int(value), dtype=np.uint16)
    elif float(np.float32(value)) == value:
        scan.attrs.create(key, value, dtype=">f4")
    else:
        scan.attrs.create(key, value, dtype=">f8")


def string_numbers(scan, key, value):
    scan.attrs[key] = repr(value)  # numbers as text, as some loggers write them


def mixed_case_keys(scan, key, value):
    default_number(scan, "_".join(part.capitalize() for part in key.split("_")).replace("Mm", "MM"), value)


def write_hdf5_variants(good, bad, columns, numbers, expected):
    def good_file(name, text=TEXT, **options):
        write_h5(os.path.join(good, name), columns, numbers, text, **options)
        expected[name] = {"text": text}

    good_file("h5py_defaults.h5", dataset_options={"compression": "gzip", "chunks": True})
    good_file("fixed_ascii_nullpad.h5", ASCII_TEXT, text_writer=fixed_ascii)
    good_file("fixed_utf8.h5", text_writer=fixed_utf8)
    good_file("fixed_ascii_nullterm.h5", ASCII_TEXT, text_writer=low_level_text(h5py.h5t.STR_NULLTERM, extra=1))
    good_file("fixed_ascii_spacepad.h5", ASCII_TEXT, text_writer=low_level_text(h5py.h5t.STR_SPACEPAD, extra=4))
    good_file("fixed_utf8_nullterm.h5", text_writer=low_level_text(h5py.h5t.STR_NULLTERM, 1, h5py.h5t.CSET_UTF8))
    good_file("one_element_arrays.h5", text_writer=array_of_one_text, number_writer=array_of_one_number)
    good_file("narrow_numbers.h5", number_writer=narrow_number)
    good_file("numbers_as_text.h5", number_writer=string_numbers)
    good_file("shuffle_fletcher32.h5",
              dataset_options={"compression": "gzip", "compression_opts": 9, "shuffle": True, "fletcher32": True})
    good_file("extendible.h5", dataset_options={"maxshape": (None,), "chunks": (4096,)})
    good_file("big_endian.h5", z=columns["z"].astype(columns["z"].dtype.newbyteorder(">")))
    good_file("libver_latest.h5", file_options={"libver": "latest"})
    good_file("lzf.h5", dataset_options={"compression": "lzf"})
    good_file("float64_z.h5", z=columns["z"].astype(np.float64))
    good_file("user_block.h5", file_options={"userblock_size": 512})
    # A sensor's own marks for its invalid readings, where the plain file has NaN: its sentinel
    # (invalid_value) and readings beyond its range, in float32 as stored.
    z = columns["z"].astype(np.float32)
    invalid = np.flatnonzero(np.isnan(z))
    z[invalid[0::2]] = np.float32(-999.0)
    z[invalid[1::2]] = np.float32(numbers["range_max_mm"] + 2.0)
    good_file("float32_sentinel.h5", z=z)
    with h5py.File(os.path.join(good, "float32_sentinel.h5"), "a") as f:
        f["scan"].attrs["invalid_value"] = -999.0
    good_file("mixed_case_keys.h5", number_writer=mixed_case_keys)
    with h5py.File(os.path.join(good, "mixed_case_keys.h5"), "a") as f:
        f["scan"].attrs["Comment"] = "dressed with a 46 um SiC stick"
    expected["mixed_case_keys.h5"]["warning"] = "metadata key 'Comment' is not one arcwheel reads"

    latin1 = dict(ASCII_TEXT, operator="M\u00fcller")
    write_h5(os.path.join(good, "latin1_operator.h5"), columns, numbers, ASCII_TEXT, text_writer=fixed_ascii)
    with h5py.File(os.path.join(good, "latin1_operator.h5"), "a") as f:
        del f["scan"].attrs["operator"]
        f["scan"].attrs["operator"] = np.bytes_("M\u00fcller".encode("latin-1"))
    expected["latin1_operator.h5"] = {"text": latin1, "warning": "metadata 'operator' is not valid UTF-8: read as Latin-1"}

    # Integer sensor counts with their scale: z = counts * scale_factor + add_offset.
    z = columns["z"].astype(np.float64)
    scale, offset = 1e-5, float(np.nanmean(z))
    counts = np.where(np.isnan(z), -2**31, np.round((z - offset) / scale)).astype(np.int32)
    write_h5(os.path.join(good, "int_counts_scaled.h5"), columns, dict(numbers, invalid_value=-2**31), TEXT, z=counts,
             z_attrs={"scale_factor": scale, "add_offset": offset})
    expected["int_counts_scaled.h5"] = {"text": TEXT, "quantum_mm": scale}

    write_h5(os.path.join(bad, "int_counts_no_scale.h5"), columns, numbers, TEXT, z=counts)
    expected["int_counts_no_scale.h5"] = {"refusal": "stores integers (sensor counts?)"}
    write_h5(os.path.join(bad, "z_2d.h5"), columns, numbers, TEXT, z=np.stack([columns["z"], columns["z"]], axis=1))
    expected["z_2d.h5"] = {"refusal": "must be one-dimensional, has rank 2"}
    text_array = os.path.join(bad, "text_array_of_two.h5")
    write_h5(text_array, columns, numbers, TEXT)
    with h5py.File(text_array, "a") as f:
        f["scan"].attrs["wheel_id"] = ["A", "B"]
    expected["text_array_of_two.h5"] = {"refusal": "holds 2 values; expected one"}
    twice = os.path.join(bad, "key_twice.h5")
    write_h5(twice, columns, numbers, TEXT)
    with h5py.File(twice, "a") as f:
        f["scan"].attrs["Radius_Sign"] = -1
    expected["key_twice.h5"] = {"refusal": "metadata 'radius_sign' is given twice"}


CSV_NAMES = {"z": "z_mm", "t": "t_s", "angle": "angle_deg", "y": "y_mm"}


def metadata_lines(numbers, text, key_case=str.lower):
    lines = [f"# {key_case(key)}: {value!r}" for key, value in numbers.items()]
    lines += [f"# {key_case(key)}: {value}" for key, value in text.items()]
    return "\n".join(lines) + "\n"


def write_csv_variants(good, columns, numbers, expected):
    # z_mm last: in a tab-separated file an invalid sample is then a trailing empty cell.
    order = [name for name in columns if name != "z"] + ["z"]
    frame = pd.DataFrame({CSV_NAMES[name]: columns[name].astype(np.float64) for name in order})
    z_only = frame[["z_mm"]]

    def good_csv(name, text=TEXT, encoding="utf-8", key_case=str.lower, frame=frame, **options):
        path = os.path.join(good, name)
        newline = options.get("lineterminator", "\n")
        with open(path, "w", encoding=encoding, newline="") as f:
            f.write(metadata_lines(numbers, text, key_case).replace("\n", newline))
            frame.to_csv(f, **options)
        expected[name] = {"text": text}

    # Floats as pandas writes them (shortest repr: they parse back to the same double).
    good_csv("pandas_defaults.csv")  # with the unnamed index column, NaN as empty cells
    good_csv("pandas_no_index.csv", index=False)
    good_csv("excel_bom_crlf.csv", encoding="utf-8-sig", index=False, lineterminator="\r\n")
    good_csv("quoted_all.csv", index=False, quoting=csv.QUOTE_ALL)
    good_csv("tab_separated.csv", index=False, sep="\t")
    good_csv("semicolon.csv", index=False, sep=";", key_case=str.upper)
    good_csv("quoted_tab_crlf.csv", index=False, sep="\t", quoting=csv.QUOTE_NONNUMERIC, lineterminator="\r\n")
    latin1 = dict(ASCII_TEXT, operator="M\u00fcller")
    good_csv("latin1_metadata.csv", text=latin1, encoding="latin-1", index=False)
    expected["latin1_metadata.csv"]["warning"] = "metadata 'operator' is not valid UTF-8: read as Latin-1"
    # pandas writes a missing value of a one-column file as "" (a blank line would end the frame).
    good_csv("pandas_one_column.csv", frame=z_only, index=False)
    expected["pandas_one_column.csv"]["z_only"] = True


def main():
    base, out = sys.argv[1], sys.argv[2]
    good, bad = os.path.join(out, "good"), os.path.join(out, "bad")
    os.makedirs(good, exist_ok=True)
    os.makedirs(bad, exist_ok=True)
    columns, numbers = read_base(base)
    expected = {}
    write_hdf5_variants(good, bad, columns, numbers, expected)
    write_csv_variants(good, columns, numbers, expected)
    with open(os.path.join(out, "expected.json"), "w", encoding="utf-8") as f:
        json.dump(expected, f, ensure_ascii=False, indent=1)


if __name__ == "__main__":
    main()
