#!/usr/bin/env python3
"""The results store end to end, through the command line, on SQLite or PostgreSQL.

    check_store.py ARCWHEEL_BINARY STORE [MIGRATION_STORE]

STORE is a SQLite file to create ("sqlite": one in the work folder) or a postgresql:// URL of an
empty database; MIGRATION_STORE
another empty one (default: a second SQLite file beside STORE's work folder). The rows are read
back with Python's sqlite3 module or with psql, not with arcwheel, and checked against the
summary.json files `arcwheel process` wrote:

  - 20 scans of two wheels recorded by `batch -j 2` (children recording at once): every scan's
    row present once, with every headline number and sigma of its summary.json and the SHA-256 of
    its scan file; a rerun records nothing twice, and records the scans it reuses into a store
    that lacks them;
  - `history --wheel` from the store writes the history.csv that `history` writes from the folders;
  - a run killed while it works, and a run that fails, leave no row;
  - a store that cannot be reached fails the run before any output, naming the store;
  - a store of schema version 1, with rows a version-1 writer made, migrated: every row kept.
"""
import hashlib
import json
import os
import pathlib
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

BINARY = os.path.realpath(sys.argv[1])
STORE = sys.argv[2]
IS_POSTGRES = STORE.startswith("postgres")

# The headline numbers summary.json holds and the store is to hold, with the key of their sigma.
CHARACTERISTICS = {
    "mean_arc_radius_mm": "mean_arc_radius_sigma_mm",
    "arc_radius_range_mm": None,
    "arc_radius_fluctuation_pct": None,
    "mean_center_axial_mm": "mean_center_axial_sigma_mm",
    "center_axial_deviation_mm": None,
    "max_arc_error_um": None,
    "max_runout_um": None,
    "max_roundness_um": None,
    "noise_sigma_um": None,
}


def run(*arguments, check=True, env=None):
    result = subprocess.run([BINARY, *arguments], capture_output=True, text=True, env=env)
    if check and result.returncode != 0:
        raise SystemExit(f"arcwheel {' '.join(arguments)} failed ({result.returncode}):\n{result.stderr}")
    return result


def query(store, sql):
    """Rows of `sql` as tuples of text (None for NULL), read without arcwheel."""
    if store.startswith("postgres"):
        out = subprocess.run(["psql", store, "-X", "-A", "-t", "-F", "\t", "-v", "ON_ERROR_STOP=1",
                              "-P", "null=\\N", "-c", sql], capture_output=True, text=True, check=True).stdout
        return [tuple(None if cell == "\\N" else cell for cell in line.split("\t"))
                for line in out.splitlines() if line]
    with sqlite3.connect(store) as db:
        return [tuple(None if cell is None else (repr(cell) if isinstance(cell, float) else str(cell))
                      for cell in row) for row in db.execute(sql)]


def execute(store, sql):
    if store.startswith("postgres"):
        subprocess.run(["psql", store, "-X", "-q", "-v", "ON_ERROR_STOP=1", "-c", sql], check=True)
    else:
        with sqlite3.connect(store) as db:
            db.executescript(sql)


def sha256(path):
    return hashlib.sha256(pathlib.Path(path).read_bytes()).hexdigest()


def check_batch(work):
    scans = work / "scans"
    scans.mkdir()
    truth = {}
    for i in range(20):
        wheel = "D15" if i % 2 == 0 else "D16"
        path = scans / f"scan_{i:02d}.h5"
        run("simulate", str(path), "--feed-mm-per-min", "800", "--noise-um", "0.5", "--seed", str(100 + i),
            "--arc-radius-mm", str(55.0 - 0.001 * i), "--wheel-id", wheel,
            "--timestamp", f"2026-03-{1 + i // 2:02d}T{8 + i % 2:02d}:30:00Z")
        truth[path.stem] = wheel
    started = time.monotonic()
    run("batch", str(scans), "-o", str(work / "out"), "-j", "2", "--db", STORE, "--", "--phases", "90",
        "--no-model")
    print(f"store test: batch -j 2 of 20 scans in {time.monotonic() - started:.1f} s")

    runs = query(STORE, "SELECT id, wheel_id, scan_timestamp, output_folder, command FROM runs")
    assert len(runs) == 20, f"{len(runs)} runs recorded, 20 expected"
    folders = [row[3] for row in runs]
    assert len(set(folders)) == 20, "a scan recorded twice"
    for run_id, wheel, timestamp, folder, command in runs:
        summary = json.loads((pathlib.Path(folder) / "summary.json").read_text())
        name = pathlib.Path(folder).name
        assert command == "process", command
        assert wheel == truth[name] == summary["scan"]["wheel_id"], (name, wheel)
        assert timestamp == summary["scan"]["timestamp"], (name, timestamp)
        numbers = {row[0]: row[1:] for row in query(
            STORE, "SELECT characteristic, value, sigma, expanded_uncertainty, decision FROM numbers "
            f"WHERE run_id = {run_id}")}
        quantities = summary["uncertainty"]["quantities"]
        for key, sigma_key in CHARACTERISTICS.items():
            assert key in numbers, (name, key, sorted(numbers))
            value, sigma, expanded, decision = numbers[key]
            # The headline figures' U from summary.json; no decision without tolerances.
            if key in quantities:
                assert float(expanded) == quantities[key]["U"], (name, key, expanded)
            else:
                assert expanded is None, (name, key, expanded)
            assert decision is None, (name, key, decision)
            assert float(value) == summary[key], (name, key, value, summary[key])
            if sigma_key:
                assert float(sigma) == summary[sigma_key], (name, sigma_key, sigma, summary[sigma_key])
            else:
                assert sigma is None, (name, key, sigma)
        inputs = query(STORE, f"SELECT role, path, sha256 FROM inputs WHERE run_id = {run_id}")
        assert len(inputs) == 1 and inputs[0][0] == "scan", inputs
        assert inputs[0][2] == sha256(scans / f"{name}.h5"), (name, inputs)

    # Run again: every scan is reused, and none recorded twice.
    batch = ["batch", str(scans), "-o", str(work / "out"), "-j", "2", "--db", STORE, "--", "--phases", "90",
             "--no-model"]
    run(*batch)
    assert int(query(STORE, "SELECT count(*) FROM runs")[0][0]) == 20
    # A store that lacks them (the first batch recorded elsewhere): the rerun records the reused scans.
    execute(STORE, "DELETE FROM numbers; DELETE FROM inputs; DELETE FROM runs;")
    run(*batch)
    rerecorded = query(STORE, "SELECT via, output_folder FROM runs")
    assert len(rerecorded) == 20 and {via for via, _ in rerecorded} == {"batch"}, rerecorded
    assert sorted(folder for _, folder in rerecorded) == sorted(folders)
    assert int(query(STORE, "SELECT count(*) FROM numbers")[0][0]) >= 20 * len(CHARACTERISTICS)
    return scans


def check_history(work):
    folders = sorted(str(p) for p in (work / "out").iterdir() if (p / "summary.json").exists())
    d15 = [f for f in folders if json.loads((pathlib.Path(f) / "summary.json").read_text())["scan"]["wheel_id"]
           == "D15"]
    assert len(d15) == 10, d15
    run("history", *d15, "-o", str(work / "history_folders"))
    run("history", "--wheel", "D15", "--db", STORE, "-o", str(work / "history_store"))
    from_folders = (work / "history_folders" / "history.csv").read_text()
    from_store = (work / "history_store" / "history.csv").read_text()
    assert from_folders == from_store, f"history differs:\n{from_folders}\n---\n{from_store}"
    # --since: the scans of March 6 on, five of them.
    run("history", "--wheel", "D15", "--since", "2026-03-06", "--db", STORE, "-o", str(work / "history_since"))
    rows = [line for line in (work / "history_since" / "history.csv").read_text().splitlines()
            if line.startswith("2026-")]
    assert len(rows) == 5 and rows[0].startswith("2026-03-06"), rows


def runs_count():
    return int(query(STORE, "SELECT count(*) FROM runs")[0][0])


def check_no_row_from_failed_runs(work, scans):
    before = runs_count()
    # A long scan, killed while it is processed.
    long_scan = work / "long.h5"
    # About a second of work (2.6 million samples, the wheel model); killed after a quarter of it.
    run("simulate", str(long_scan), "--feed-mm-per-min", "5", "--noise-um", "0.5", "--wheel-id", "D17")
    child = subprocess.Popen([BINARY, "process", str(long_scan), "-o", str(work / "killed"), "--db", STORE],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.25)
    assert child.poll() is None, "the long scan finished before it could be killed"
    child.send_signal(signal.SIGKILL)
    child.wait()
    assert runs_count() == before, "a killed run left a row"
    # A run that fails: not a scan.
    bad = work / "bad.csv"
    bad.write_text("this is not a scan\n")
    result = run("process", str(bad), "-o", str(work / "failed"), "--db", STORE, check=False)
    assert result.returncode != 0 and not (work / "failed").exists(), result
    assert runs_count() == before, "a failed run left a row"
    # A store that cannot be reached: the run fails before it writes anything, naming the store.
    unreachable = ("postgresql://arcwheel@127.0.0.1:1/none?connect_timeout=3" if IS_POSTGRES
                   else str(work / "no such folder" / "results.sqlite"))
    shown = unreachable if not IS_POSTGRES else "127.0.0.1:1"
    result = run("process", str(scans / "scan_00.h5"), "-o", str(work / "unreached"), "--db", unreachable,
                 check=False)
    assert result.returncode == 4, result
    assert shown in result.stderr, result.stderr
    assert not (work / "unreached").exists(), "output written although the store cannot be reached"


def check_migration(work, store):
    run("db", "init", "--schema-version", "1", "--db", store)
    assert query(store, "SELECT version FROM schema_version") == [("1",)]
    # Rows as a version-1 arcwheel wrote them.
    statements = []
    for i in range(1, 6):
        statements.append(
            "INSERT INTO runs (command, via, wheel_id, scan_timestamp, scan_time_s, recorded_at, "
            f"arcwheel_version, output_folder, options) VALUES ('process', 'process', 'D15', "
            f"'2026-02-0{i}T08:00:00Z', {1769932800 + 86400 * (i - 1)}, '2026-02-0{i}T09:00:00Z', '0.1.0', "
            f"'/results/{i}', '{{}}');")
        statements.append(f"INSERT INTO numbers (run_id, characteristic, value, sigma, unit) VALUES ({i}, "
                          f"'mean_arc_radius_mm', {55 + i / 8}, 0.001, 'mm');")
        statements.append(f"INSERT INTO inputs (run_id, role, path, sha256) VALUES ({i}, 'scan', '/s{i}.h5', "
                          f"'{i:064d}');")
    execute(store, "\n".join(statements))
    # Refused for recording until migrated, with the command that fixes it.
    result = run("process", str(work / "scans" / "scan_00.h5"), "-o", str(work / "v1"), "--db", store,
                 check=False)
    assert result.returncode != 0 and "db migrate" in result.stderr, result.stderr
    run("db", "migrate", "--db", store)
    assert query(store, "SELECT version FROM schema_version") == [("2",)]
    runs = query(store, "SELECT id, output_folder, host FROM runs ORDER BY id")
    assert runs == [(str(i), f"/results/{i}", "") for i in range(1, 6)], runs
    numbers = query(store, "SELECT run_id, value, expanded_uncertainty FROM numbers ORDER BY run_id")
    assert [(int(r), float(v), u) for r, v, u in numbers] == [(i, 55 + i / 8, None) for i in range(1, 6)], numbers
    assert len(query(store, "SELECT * FROM inputs")) == 5
    exported = json.loads(run("db", "export", "--json", "--db", store).stdout)
    assert [row["value"] for row in exported["rows"]] == [55 + i / 8 for i in range(1, 6)], exported
    # The migrated store records a new run.
    run("process", str(work / "scans" / "scan_00.h5"), "-o", str(work / "v2"), "--db", store, "--phases", "90",
        "--no-model")
    assert len(query(store, "SELECT id FROM runs")) == 6


def check_decisions(work, scans):
    """`process --tolerances --db`: each toleranced number's decision as summary.json has it."""
    tolerances = work / "tolerances.json"
    tolerances.write_text(json.dumps({"max_runout_um": 1000.0, "mean_arc_radius_mm": {"max": 54.9}}))
    out = work / "decided"
    run("process", str(scans / "scan_00.h5"), "-o", str(out), "-q", "--phases", "90", "--no-model",
        "--tolerances", str(tolerances), "--db", STORE)
    summary = json.loads((out / "summary.json").read_text())
    decisions = summary["uncertainty"]["decisions"]
    assert decisions["max_runout_um"]["decision"] == "conforms", decisions
    assert decisions["mean_arc_radius_mm"]["decision"] == "does not conform", decisions  # a 55 mm arc
    run_id = query(STORE, f"SELECT id FROM runs WHERE output_folder = '{out.resolve()}'")[0][0]
    stored = dict(query(STORE, f"SELECT characteristic, decision FROM numbers WHERE run_id = {run_id}"))
    assert stored["max_runout_um"] == "conforms" and stored["mean_arc_radius_mm"] == "does not conform", stored
    assert stored["max_arc_error_um"] is None, stored


def main():
    global STORE
    with tempfile.TemporaryDirectory(prefix="arcwheel-store-") as folder:
        work = pathlib.Path(folder)
        if STORE == "sqlite":
            STORE = str(work / "results.sqlite")
        scans = check_batch(work)
        check_history(work)
        check_decisions(work, scans)
        check_no_row_from_failed_runs(work, scans)
        check_migration(work, sys.argv[3] if len(sys.argv) > 3 else str(work / "v1.sqlite"))
        exported = run("db", "export", "--csv", "--db", STORE).stdout.splitlines()
        assert len(exported) == 1 + sum(int(r[0]) for r in query(STORE, "SELECT count(*) FROM numbers")), exported[:3]
    print(f"store test: passed on {'PostgreSQL' if IS_POSTGRES else 'SQLite'}")


main()
