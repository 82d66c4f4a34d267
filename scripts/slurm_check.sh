#!/usr/bin/env bash
# CI check of issue 31: the quick fold study, stability matrix and convergence study, each run serially,
# with the local executor (-j 2) and as a Slurm job array on a one-node cluster started here
# (scripts/slurm_local.sh, as root), give the same results.csv in every column but wall_seconds;
# `clothsim figures 10 --quick` the same fig10.png and fig10.md (wall times aside).
# Prints the wall times and Slurm's dispatch overhead per task. Needs a built build/release/clothsim (scripts/test.sh) or CLOTHSIM_BIN.
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
slurm_dir="${CLOTHSIM_SLURM_DIR:-/run/clothsim-slurm}"
export SLURM_CONF="$slurm_dir/slurm.conf"
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

t=$(now)
if [ -s "$slurm_dir/slurmctld.pid" ] && kill -0 "$(cat "$slurm_dir/slurmctld.pid")" 2>/dev/null; then
  echo "slurm_check: using the running cluster ($SLURM_CONF)"
else
  started=1
  scripts/slurm_local.sh start
fi
cluster=$(since "$t")

summary=""
for name in folds stability convergence; do
  study=(study "$name" --quick --no-plot)
  t=$(now)
  # The convergence study's static plate solves factorise with CHOLMOD, whose supernodal BLAS sums
  # in another order with another thread count (round-off at 1e-15); -j 2 and the Slurm tasks run
  # with one BLAS thread each, so the serial run does too.
  blas=()
  [ "$name" = convergence ] && blas=(env OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1)
  "${blas[@]}" "$bin" "${study[@]}" --out "$tmp/serial" 2>"$tmp/serial_$name.log" >/dev/null
  serial=$(since "$t")
  t=$(now)
  "$bin" "${study[@]}" -j 2 --out "$tmp/local" 2>"$tmp/local_$name.log" | grep '^local:' ||
    { cat "$tmp/local_$name.log" >&2; exit 1; }
  local_j2=$(since "$t")
  t=$(now)
  "$bin" "${study[@]}" --executor slurm --slurm-time 10 --slurm-mem 1G --out "$tmp/slurm" 2>"$tmp/slurm_$name.log" |
    grep '^slurm:' || { cat "$tmp/slurm_$name.log" >&2; exit 1; }
  slurm=$(since "$t")
  summary+="slurm_check: quick $name study wall times: serial $serial s, local -j 2 $local_j2 s, slurm $slurm s"$'\n'
done

# clothsim figures 10 --quick (its four runs as tasks): the same fig10.png, fig10.md but for the
# runs' wall times.
t=$(now)
"$bin" figures 10 --quick --out "$tmp/serial" 2>"$tmp/serial_figures.log" >/dev/null
serial=$(since "$t")
t=$(now)
"$bin" figures 10 --quick -j 2 --out "$tmp/local" 2>"$tmp/local_figures.log" | grep '^local:' ||
  { cat "$tmp/local_figures.log" >&2; exit 1; }
local_j2=$(since "$t")
t=$(now)
"$bin" figures 10 --quick --executor slurm --slurm-time 10 --slurm-mem 1G --out "$tmp/slurm" 2>"$tmp/slurm_figures.log" |
  grep '^slurm:' || { cat "$tmp/slurm_figures.log" >&2; exit 1; }
slurm=$(since "$t")
summary+="slurm_check: quick figure 10 wall times: serial $serial s, local -j 2 $local_j2 s, slurm $slurm s"$'\n'
for other in local slurm; do
  cmp "$tmp/serial/figures/fig10.png" "$tmp/$other/figures/fig10.png" ||
    { echo "slurm_check: error: $other's fig10.png is not the serial run's" >&2; exit 1; }
  diff <(sed 's/| [^|]* |$//' "$tmp/serial/figures/fig10.md") <(sed 's/| [^|]* |$//' "$tmp/$other/figures/fig10.md") >&2 ||
    { echo "slurm_check: error: $other's fig10.md differs from the serial run's (wall times aside)" >&2; exit 1; }
done
echo "slurm_check: figures: fig10.png and fig10.md of -j 2 and of slurm equal the serial run's (wall times aside)"

# results.csv without wall_seconds, compared with the serial run's.
/usr/bin/python3 - "$tmp" <<'PY'
import csv, sys
tmp = sys.argv[1]
def rows(run, study):
    with open(f"{tmp}/{run}/study_{study}/results.csv", newline="") as f:
        table = list(csv.reader(f))
    drop = table[0].index("wall_seconds")
    return [r[:drop] + r[drop + 1:] for r in table]
for study in ("folds", "stability", "convergence"):
    serial = rows("serial", study)
    for other in ("local", "slurm"):
        got = rows(other, study)
        if got != serial:
            for a, b in zip(serial, got):
                if a != b:
                    print(f"slurm_check: {other} differs from serial:\n  {a}\n  {b}", file=sys.stderr)
            sys.exit(f"slurm_check: error: {other}/study_{study}/results.csv is not the serial run's")
    print(f"slurm_check: {study}: results.csv of -j 2 and of slurm equal the serial run's "
          f"({len(serial) - 1} rows, every column but wall_seconds)")
PY
printf '%s' "$summary"
echo "slurm_check: cluster start $cluster s"
