#!/usr/bin/python3
"""Writes a grid map (docs/outputs.md, "Grid maps") with h5py (Debian's python3-h5py), as another
tool would, for tests/regenerate_test.cc.

    write_grid_map.py OUTDIR

OUTDIR/grid_map.h5: root dataset error_um [ny][nx] as float32 (arcwheel writes float64), NaN at
one node, root attributes x0_mm, y0_mm, dx_mm, dy_mm as numpy scalars of mixed types, and
schema_version as a fixed-length byte string. OUTDIR/expected.json gives every node's position
and value (null = no data) as computed here from what was written.
"""

import json
import os
import sys

import h5py
import numpy as np


def main(outdir):
    nx, ny = 5, 3
    x0, y0, dx, dy = -10.0, 4.5, 2.5, 1.25
    values = np.array([[0.25 * i - 0.5 * j for i in range(nx)] for j in range(ny)], dtype=np.float32)
    values[1, 3] = np.nan
    with h5py.File(os.path.join(outdir, "grid_map.h5"), "w") as f:
        f.create_dataset("error_um", data=values)
        f.attrs["x0_mm"] = np.float64(x0)
        f.attrs["y0_mm"] = np.float32(y0)
        f.attrs["dx_mm"] = np.float64(dx)
        f.attrs["dy_mm"] = np.float64(dy)
        f.attrs["schema_version"] = np.bytes_("1.0")
        f.attrs["quantity"] = "error map"
    nodes = []
    for j in range(ny):
        for i in range(nx):
            v = float(values[j, i])
            nodes.append({"x_mm": x0 + i * dx, "y_mm": y0 + j * dy, "error_um": None if np.isnan(v) else v})
    with open(os.path.join(outdir, "expected.json"), "w") as out:
        json.dump({"nx": nx, "ny": ny, "nodes": nodes}, out)


if __name__ == "__main__":
    main(sys.argv[1])
