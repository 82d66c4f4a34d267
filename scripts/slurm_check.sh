#!/usr/bin/env bash
# CI check of issue 31: the quick fold study run serially, with the local executor (-j 2) and as a
# Slurm job array on a one-node cluster started here (scripts/slurm_local.sh, as root) gives the
# same results.csv in every column but wall_seconds. Prints the wall times and Slurm's overhead
# per task. Needs a built build/release/clothsim (scripts/test.sh) or CLOTHSIM_BIN.
# Usage: scripts/slurm_check.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(readlink -f "${CLOTHSIM_BIN:-build/release/clothsim}")
[ -x "$bin" ] || { echo "slurm_check: error: $bin is not built (scripts/test.sh builds it)" >&2; exit 1; }
tmp=$(mktemp -d /tmp/clothsim_slurm_check.XXXXXX)
started=0
cleanup() {
  [ $started = 1 ] && scripts/slurm_local.sh stop || true
  rm -rf "$tmp"
}
trap cleanup EXIT
export SLURM_CONF="${CLOTHSIM_SLURM_DIR:-/run/clothsim-slurm}/slurm.conf"

study=(study folds --quick --no-plot)
t=$SECONDS
"$bin" "${study[@]}" --out "$tmp/serial" 2>"$tmp/serial.log"
serial=$((SECONDS - t))
t=$SECONDS
"$bin" "${study[@]}" -j 2 --out "$tmp/local" 2>"$tmp/local.log" | tee "$tmp/local.out"
local_j2=$((SECONDS - t))

t=$SECONDS
if [ -f "$SLURM_CONF" ] && sinfo -h >/dev/null 2>&1; then
  echo "slurm_check: using the running cluster ($SLURM_CONF)"
else
  started=1
  scripts/slurm_local.sh start
fi
cluster=$((SECONDS - t))
t=$SECONDS
"$bin" "${study[@]}" --executor slurm --slurm-time 10 --slurm-mem 1G --out "$tmp/slurm" 2>"$tmp/slurm.log" |
  tee "$tmp/slurm.out" || { cat "$tmp/slurm.log" >&2; exit 1; }
slurm=$((SECONDS - t))

# results.csv without wall_seconds, compared with the serial run's.
/usr/bin/python3 - "$tmp" <<'PY'
import csv, sys
tmp = sys.argv[1]
def rows(name):
    with open(f"{tmp}/{name}/study_folds/results.csv", newline="") as f:
        table = list(csv.reader(f))
    drop = table[0].index("wall_seconds")
    return [r[:drop] + r[drop + 1:] for r in table]
serial = rows("serial")
for other in ("local", "slurm"):
    got = rows(other)
    if got != serial:
        for a, b in zip(serial, got):
            if a != b:
                print(f"slurm_check: {other} differs from serial:\n  {a}\n  {b}", file=sys.stderr)
        sys.exit(f"slurm_check: error: {other}/study_folds/results.csv is not the serial run's ({len(got) - 1} rows)")
print(f"slurm_check: results.csv of -j 2 and of slurm equal the serial run's ({len(serial) - 1} rows, every column but wall_seconds)")
PY
echo "slurm_check: quick fold study wall times: serial ${serial} s, local -j 2 ${local_j2} s, slurm ${slurm} s (cluster start ${cluster} s)"
