#!/usr/bin/env bash
# `arcwheel batch --emit-slurm` on a real Slurm: a single-node cluster on this machine, for
# localhost only, started here (as root) with its state, keys and logs in a temporary folder,
# three simulated scans run as an array job (`sbatch --wait`), then the index built by
# `arcwheel batch --index-only` and checked against the scans' truth. Everything it started is
# stopped on exit. Needs root, slurm-wlm and munge (scripts/packages.txt).
#
#   tests/slurm/run_slurm_test.sh [ARCWHEEL_BINARY]      (default build/cli/arcwheel)
#
# The whole run is bounded: SLURM_TEST_TIMEOUT_S (default 180 s) for the job, 60 s for each
# daemon to come up. Exit status 0 when the index is right, else non-zero with the daemons' logs.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
binary=$(realpath "${1:-$root/build/cli/arcwheel}")
timeout_s=${SLURM_TEST_TIMEOUT_S:-180}
start=$SECONDS

if [[ $(id -u) -ne 0 ]]; then
  # slurmd starts each job as its user, so the daemons run as root.
  command -v sudo >/dev/null || { echo "slurm test: run as root or install sudo" >&2; exit 1; }
  exec sudo --preserve-env=SLURM_TEST_TIMEOUT_S "$0" "$binary"
fi
for tool in munged mungekey slurmctld slurmd sbatch sinfo python3; do
  command -v "$tool" >/dev/null || { echo "slurm test: '$tool' is missing (scripts/install_deps.sh)" >&2; exit 1; }
done

work=$(mktemp -d /tmp/arcwheel-slurm.XXXXXX)
chmod 755 "$work"
pids=()
show_logs() {
  for log in "$work"/*.log "$work"/*.out "$work"/*/logs/*; do
    [[ -f "$log" ]] || continue
    echo "----- $log (last 30 lines)" >&2
    tail -n 30 "$log" >&2
  done
}
cleanup() {
  local status=$?
  ((status == 0)) || show_logs
  # Jobs still queued or running (a timeout) are cancelled before their daemons stop.
  if [[ -n "${SLURM_CONF:-}" ]] && squeue -h -o %A >"$work/left" 2>/dev/null && [[ -s "$work/left" ]]; then
    xargs -r scancel <"$work/left" || true
    for _ in $(seq 100); do [[ -z $(squeue -h -o %A 2>/dev/null) ]] && break; sleep 0.1; done
  fi
  # Only the daemons this script started, by their process ids.
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
  local limit=$1
  shift
  local deadline=$((SECONDS + limit))
  until "$@" >/dev/null 2>&1; do
    if ((SECONDS >= deadline)); then
      echo "slurm test: gave up after ${limit} s waiting for: $*" >&2
      return 1
    fi
    sleep 0.2
  done
}

# Two free TCP ports on localhost for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
sockets = [socket.socket() for _ in range(2)]
for s in sockets: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in sockets])')

# munge: a fresh key and a socket of our own, so that a system munged (if any) is not touched.
mungekey --create --keyfile="$work/munge.key"
chmod 400 "$work/munge.key"
mkdir -m 711 "$work/munge"
munged --foreground --force --key-file="$work/munge.key" --socket="$work/munge/munge.socket" \
  --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge.seed" \
  >"$work/munged.out" 2>&1 &
pids+=($!)
wait_for 60 test -S "$work/munge/munge.socket"

# The node as slurmd sees it (hostname, CPUs, memory): its own `slurmd -C` line.
node_line=$(slurmd -C | head -n 1)
node=$(hostname -s)
mkdir -p "$work/state" "$work/spool"
cat >"$work/slurm.conf" <<CONF
ClusterName=arcwheeltest
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
KillWait=5
$node_line NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -D -i >"$work/slurmctld.out" 2>&1 &
pids+=($!)
wait_for 60 scontrol ping
slurmd -D -N "$node" >"$work/slurmd.out" 2>&1 &
pids+=($!)
wait_for 60 bash -c "sinfo -h -n '$node' -o %t | grep -qx idle"
echo "slurm test: cluster up after $((SECONDS - start)) s"

# Three scans of known arc radius, one of them CSV.
mkdir "$work/scans"
radii=(54.0 55.5 57.0)
for i in 0 1 2; do
  ext=h5
  ((i == 2)) && ext=csv
  "$binary" simulate "$work/scans/wheel_$i.$ext" --feed-mm-per-min 400 --noise-um 0.5 --seed $((40 + i)) \
    --arc-radius-mm "${radii[$i]}" >/dev/null
done
# The results go to a folder whose name has a space and a '#', which the script's #SBATCH lines
# must quote for sbatch.
out="$work/batch out #1"
"$binary" batch "$work/scans" -o "$out" --emit-slurm "$work/job.sh" -- --phases 180
job_id=$(timeout "$timeout_s" sbatch --parsable --wait "$work/job.sh") || {
  echo "slurm test: sbatch --wait failed or took over ${timeout_s} s" >&2
  squeue >&2 || true
  exit 1
}
echo "slurm test: array job $job_id ended after $((SECONDS - start)) s"
"$binary" batch "$work/scans" -o "$out" --index-only -- --phases 180

# The index: three results, each from the Slurm task (its log), with the truth's arc radius.
python3 - "$out" <<'PY'
import json, pathlib, statistics, sys
out = pathlib.Path(sys.argv[1])
index = json.loads((out / "index.json").read_text())
rows = index["scans"]
assert len(rows) == 3, rows
for row in rows:
    assert row["status"] == "done", row
    scan = pathlib.Path(row["scan"])
    truth = json.loads(pathlib.Path(str(scan) + ".truth.json").read_text())
    want = statistics.fmean(truth["phases"]["arc_radius_mm"])
    got, sigma = row["mean_arc_radius_mm"], row["mean_arc_radius_sigma_mm"]
    assert abs(got - want) < 3 * sigma, (scan.name, got, want, sigma)
    summary = json.loads((pathlib.Path(row["result"]) / "summary.json").read_text())
    assert summary["processing"]["phases"] == 180, summary["processing"]
    print(f"slurm test: {scan.name}: {got:.5f} mm, truth {want:.5f} mm, sigma {sigma:.5f} mm")
tasks = sorted((out / "logs").glob("slurm-*_*.out"))
assert len(tasks) == 3, tasks
PY
echo "slurm test: passed in $((SECONDS - start)) s"
