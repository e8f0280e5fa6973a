#!/usr/bin/python3
"""Writes small Zygo Mx .datx files with h5py (Debian's python3-h5py) in the layouts real
instruments write, for polishing/error_map_io_test.cc.

    write_datx.py OUTDIR

OUTDIR/good holds files that must read; OUTDIR/bad files that must be refused; OUTDIR/expected.json
gives, for each good file, its size, lateral resolution and every pixel's height in micrometres
(null = no data) as computed here from the numbers written, and for each bad file a part of the
message that must name the reason.

The layouts:
  - "metadata": as MetroPro 8.3 writes a measurement: the surface at /Data/Surface/{GUID}, found
    through the /MetaData table (a compound of three variable-length ASCII strings Source, Link,
    Destination: Root -> Measurement -> {M}, {M} -> Surface -> {S}, {S} -> Path -> the dataset),
    heights in Fringes with Wavelength, Interferometric Scale Factor and Obliquity Factor, the
    largest double as No Data, converters as compounds of variable-length strings and a
    variable-length float64 Parameters; beside it the other groups such a file holds.
  - "measurement": /Measurement/Surface with fixed-length converter strings, heights in nanometres
    and NaN as No Data.
  - "data_surface_only": no /MetaData and no /Measurement; one dataset under /Data/Surface.
"""

import ctypes
import json
import os
import sys

import h5py
import numpy as np

ASCII = h5py.string_dtype("ascii")
FIXED_CONVERTER = np.dtype([("Category", "S16"), ("BaseUnit", "S16"), ("Parameters", np.float64, (4,))])
METADATA = np.dtype([("Source", ASCII), ("Link", ASCII), ("Destination", ASCII)])
COORDINATES = np.dtype([("RowStart", "<i4"), ("ColumnStart", "<i4"), ("Width", "<i4"), ("Height", "<i4")])

ROWS, COLUMNS = 9, 6
WAVELENGTH_M = 6.327999813038332e-07
SCALE_FACTOR = 0.5
OBLIQUITY = 1.0
PIXEL_M = 1.17924e-4

MEASUREMENT_GUID = "{09244224-74DD-4E34-BC45-39F039673A6A}"
SURFACE_GUID = "{1CE20D93-8A91-4847-9CEF-B83B2F42271E}"
ATTRIBUTES_GUID = "{846C2331-6472-411F-9024-179B928C018D}"


def heights_in_unit(scale):
    """A tilted bowl with a ring of pixels without data (NaN), in the file's unit."""
    rows, columns = np.mgrid[0:ROWS, 0:COLUMNS]
    values = scale * (0.3 * (rows - 4.0) ** 2 - 0.2 * (columns - 2.5) ** 2 + 0.05 * rows * columns - 0.11)
    values[0, :2] = np.nan
    values[ROWS - 1, COLUMNS - 1] = np.nan
    values[4, 3] = np.nan
    return values


def write_converter(node, name, category, unit, parameters, fixed=False):
    """A Zygo converter attribute. MetroPro's form, {variable-length ASCII Category and BaseUnit,
    variable-length float64 Parameters}, is written through h5py's low-level API from a C struct
    {char*, char*, hvl_t}: h5py 3.7's own conversion of a compound attribute with several
    variable-length members crashes (h5py issue 596)."""
    if fixed:
        node.attrs[name] = np.array([(category.encode(), unit.encode(), parameters)], dtype=FIXED_CONVERTER)
        return
    strings = [ctypes.create_string_buffer(category.encode()), ctypes.create_string_buffer(unit.encode())]
    values = np.ascontiguousarray(parameters, dtype=np.float64)
    raw = np.zeros(1, dtype=[("category", "<u8"), ("unit", "<u8"), ("length", "<u8"), ("values", "<u8")])
    raw["category"] = ctypes.addressof(strings[0])
    raw["unit"] = ctypes.addressof(strings[1])
    raw["length"] = values.size
    raw["values"] = values.ctypes.data
    text = h5py.h5t.C_S1.copy()
    text.set_size(h5py.h5t.VARIABLE)
    text.set_cset(h5py.h5t.CSET_ASCII)
    converter = h5py.h5t.create(h5py.h5t.COMPOUND, raw.dtype.itemsize)
    converter.insert(b"Category", 0, text)
    converter.insert(b"BaseUnit", 8, text)
    converter.insert(b"Parameters", 16, h5py.h5t.vlen_create(h5py.h5t.NATIVE_DOUBLE))
    attribute = h5py.h5a.create(node.id, name.encode(), converter, h5py.h5s.create_simple((1,)))
    attribute.write(raw, mtype=converter)


def write_surface(group, name, values_in_unit, no_data, unit, *, fixed=False, fringes=False):
    stored = np.where(np.isnan(values_in_unit), no_data, values_in_unit)
    surface = group.create_dataset(name, data=stored.astype(np.float64))
    surface.attrs["Coordinates"] = np.array([(22, 15, COLUMNS, ROWS)], dtype=COORDINATES)
    surface.attrs["Group Number"] = np.array([1], dtype=np.int32)
    surface.attrs["No Data"] = np.array([no_data])
    surface.attrs["Unit"] = np.array([unit], dtype=ASCII)
    if fringes:
        surface.attrs["Interferometric Scale Factor"] = np.array([SCALE_FACTOR])
        surface.attrs["Obliquity Factor"] = np.array([OBLIQUITY])
        surface.attrs["Wavelength"] = np.array([WAVELENGTH_M])
        z_parameters = [0.0, WAVELENGTH_M, SCALE_FACTOR, OBLIQUITY]
    else:
        z_parameters = [0.0, 0.0, 0.0, 0.0]
    lateral = [0.0, PIXEL_M, 0.0, 0.0]
    write_converter(surface, "X Converter", "LateralCat", "Pixels", lateral, fixed)
    write_converter(surface, "Y Converter", "LateralCat", "Pixels", lateral, fixed)
    write_converter(surface, "Z Converter", "HeightCat", unit, z_parameters, fixed)
    return surface


def metadata_rows(surface_path):
    return [
        ("Root", "Attributes", "/Attributes/System"),
        ("Root", "Measurement", MEASUREMENT_GUID),
        (MEASUREMENT_GUID, "Attributes", "/Attributes/" + ATTRIBUTES_GUID),
        (MEASUREMENT_GUID, "Surface", SURFACE_GUID),
        (MEASUREMENT_GUID, "Group Number", "1"),
        (MEASUREMENT_GUID, "Element Type", "Measurement"),
        (MEASUREMENT_GUID, "Name", "Processed Data: /PM-Gpi/AP_DS:Processed Data/Plot"),
        (SURFACE_GUID, "Path", surface_path),
        (SURFACE_GUID, "Name", "Surface"),
        (SURFACE_GUID, "MpxDataType", "DoubleMatrix2D"),
    ]


def write_metadata_layout(path, values, *, rows=None, extra_surface=False):
    """MetroPro's layout: the surface at /Data/Surface/{GUID}, found through /MetaData."""
    with h5py.File(path, "w") as f:
        f.create_group("Attributes/System")
        f.create_group("Attributes/" + ATTRIBUTES_GUID).attrs["Data Context.Data Attributes.Wavelength"] = "632.8 nm"
        data = f.create_group("Data")
        # Byte blobs beside the surface, as MetroPro stores its other records.
        data.create_dataset("{3AD5CF24-EE4A-49B2-B550-DAEF948C76A6}", data=np.zeros(1024, dtype=np.uint8))
        write_surface(data.create_group("Surface"), SURFACE_GUID, values, np.finfo(np.float64).max, "Fringes",
                      fringes=True)
        if extra_surface:
            write_surface(data["Surface"], "{00000000-0000-0000-0000-000000000000}", values,
                          np.finfo(np.float64).max, "Fringes", fringes=True)
        table = rows if rows is not None else metadata_rows("/Data/Surface/" + SURFACE_GUID)
        metadata = f.create_dataset("MetaData", shape=(len(table),), dtype=METADATA, chunks=(len(table),),
                                    maxshape=(None,))
        metadata[...] = np.array(table, dtype=METADATA)
        f.create_group("Processed Data: /PM-Gpi/AP_DS:Processed Data/Plot")


def write_measurement_layout(path, values):
    with h5py.File(path, "w") as f:
        write_surface(f.create_group("Measurement"), "Surface", values, np.nan, "NanoMeters", fixed=True)


def write_data_surface_only(path, values, *, datasets=1):
    with h5py.File(path, "w") as f:
        group = f.create_group("Data/Surface")
        for k in range(datasets):
            write_surface(group, "{%08d-0000-0000-0000-000000000000}" % k, values, np.finfo(np.float64).max,
                          "Fringes", fringes=True)


def expected_entry(values_in_unit, um_per_unit):
    heights = values_in_unit * um_per_unit
    valid = heights[~np.isnan(heights)]
    return {
        "width": COLUMNS,
        "height": ROWS,
        "pixel_mm": PIXEL_M * 1e3,
        "height_um": [[None if np.isnan(h) else float(h) for h in row] for row in heights],
        "valid_pixels": int(valid.size),
        "pv_um": float(valid.max() - valid.min()),
        "rms_um": float(np.sqrt(np.mean((valid - valid.mean()) ** 2))),
    }


def main():
    out = sys.argv[1]
    good, bad = os.path.join(out, "good"), os.path.join(out, "bad")
    os.makedirs(good, exist_ok=True)
    os.makedirs(bad, exist_ok=True)
    fringes = heights_in_unit(1.0)
    nanometres = heights_in_unit(80.0)
    um_per_fringe = WAVELENGTH_M * SCALE_FACTOR * OBLIQUITY * 1e6
    expected = {"good": {}, "bad": {}}

    write_metadata_layout(os.path.join(good, "metadata.datx"), fringes)
    expected["good"]["metadata.datx"] = expected_entry(fringes, um_per_fringe)
    write_measurement_layout(os.path.join(good, "measurement.datx"), nanometres)
    expected["good"]["measurement.datx"] = expected_entry(nanometres, 1e-3)
    write_data_surface_only(os.path.join(good, "data_surface_only.datx"), fringes)
    expected["good"]["data_surface_only.datx"] = expected_entry(fringes, um_per_fringe)
    # /MetaData decides even where a /Measurement/Surface and a second dataset stand beside it.
    write_metadata_layout(os.path.join(good, "metadata_first.datx"), fringes, extra_surface=True)
    with h5py.File(os.path.join(good, "metadata_first.datx"), "a") as f:
        write_surface(f.create_group("Measurement"), "Surface", nanometres, np.nan, "NanoMeters")
    expected["good"]["metadata_first.datx"] = expected_entry(fringes, um_per_fringe)

    rows = metadata_rows("/Data/Surface/{FFFFFFFF-0000-0000-0000-000000000000}")
    write_metadata_layout(os.path.join(bad, "metadata_names_missing_path.datx"), fringes, rows=rows)
    expected["bad"]["metadata_names_missing_path.datx"] = "which the file does not hold"
    rows = metadata_rows("/Data/Surface/" + SURFACE_GUID) + [(MEASUREMENT_GUID, "Surface", "{OTHER}")]
    write_metadata_layout(os.path.join(bad, "metadata_two_surfaces.datx"), fringes, rows=rows)
    expected["bad"]["metadata_two_surfaces.datx"] = "links '" + MEASUREMENT_GUID + "' -> 'Surface' to both"
    write_data_surface_only(os.path.join(bad, "two_unnamed_surfaces.datx"), fringes, datasets=2)
    expected["bad"]["two_unnamed_surfaces.datx"] = "'/Data/Surface' holds 2 datasets"
    with h5py.File(os.path.join(bad, "no_surface.datx"), "w") as f:
        f.create_group("Data/Surface")
    expected["bad"]["no_surface.datx"] = "no surface dataset"
    damaged = fringes.copy()
    damaged[2, 5] = np.inf
    write_metadata_layout(os.path.join(bad, "infinity.datx"), damaged)
    expected["bad"]["infinity.datx"] = "value [2][5] = inf is not a finite height"

    with open(os.path.join(out, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)


if __name__ == "__main__":
    main()
