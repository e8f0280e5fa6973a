#!/usr/bin/env bash
# The results store on a real PostgreSQL server: a private cluster in a temporary folder
# (initdb, then pg_ctl start listening only on a unix socket in that folder), two empty databases,
# and tests/store/check_store.py run against them (20 scans by `batch -j 2`, history from the
# store, killed and failed runs, a migration from schema version 1). The server is stopped and
# the folder removed on exit. initdb refuses to run as root, so the server runs as the `postgres`
# user of Debian's postgresql package; this script runs as root (CI) or through sudo.
#
#   tests/store/run_postgres_test.sh [ARCWHEEL_BINARY]      (default build/cli/arcwheel)
#
# Bounded: 60 s for the server to start; .ci/run bounds the whole run with `timeout`.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
binary=$(realpath "${1:-$root/build/cli/arcwheel}")
start=$SECONDS

if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "postgres test: run as root or install sudo" >&2; exit 1; }
  exec sudo "$0" "$binary"
fi
bin=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
for tool in "$bin/initdb" "$bin/pg_ctl" "$bin/createdb" psql runuser python3; do
  command -v "$tool" >/dev/null || { echo "postgres test: '$tool' is missing (scripts/install_deps.sh)" >&2; exit 1; }
done
id postgres >/dev/null 2>&1 || { echo "postgres test: no 'postgres' user (Debian's postgresql package)" >&2; exit 1; }

work=$(mktemp -d /tmp/arcwheel-pg.XXXXXX)
chmod 755 "$work"
mkdir -m 700 "$work/data"
mkdir "$work/socket"
chown postgres: "$work/data" "$work/socket"
as_postgres() { runuser -u postgres -- "$@"; }
started=0
cleanup() {
  local status=$?
  if ((status != 0)) && [[ -f "$work/server.log" ]]; then
    echo "----- $work/server.log (last 30 lines)" >&2
    tail -n 30 "$work/server.log" >&2
  fi
  # Only the server this script started, by its data folder.
  if ((started)); then as_postgres "$bin/pg_ctl" stop -D "$work/data" -m immediate -s >/dev/null 2>&1 || true; fi
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

as_postgres "$bin/initdb" -D "$work/data" -U postgres -A trust --no-sync -E UTF8 >"$work/initdb.log" 2>&1 || {
  cat "$work/initdb.log" >&2
  exit 1
}
touch "$work/server.log" && chown postgres: "$work/server.log"
# No TCP port: only the socket in our folder, so that nothing else on this machine is touched.
started=1
as_postgres "$bin/pg_ctl" start -D "$work/data" -l "$work/server.log" -w -t 60 -s \
  -o "-c listen_addresses='' -k $work/socket -c fsync=off"
as_postgres "$bin/createdb" -h "$work/socket" results
as_postgres "$bin/createdb" -h "$work/socket" migration
echo "postgres test: server up after $((SECONDS - start)) s"

url="postgresql:///results?host=$work/socket&user=postgres"
migration_url="postgresql:///migration?host=$work/socket&user=postgres"
python3 "$root/tests/store/check_store.py" "$binary" "$url" "$migration_url"
echo "postgres test: passed in $((SECONDS - start)) s"
