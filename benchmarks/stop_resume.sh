#!/usr/bin/env bash
# Stop-and-resume check with timings: a demo run on CartPole,MountainCar is stopped with
# SIGTERM after generation ~13, resumed, and compared with an uninterrupted run (every
# metrics.csv column but the timing ones, tests.csv, tests/, champions/). Prints how long
# the stopped process took to exit after the signal (at most one generation plus a commit).
#
# Usage: bash benchmarks/stop_resume.sh [PRESET] [GENERATIONS]   (defaults: demo 30)
set -euo pipefail
mtpg=${MTPG:-.venv/bin/mtpg}
preset=${1:-demo}
gens=${2:-30}
w=$(mktemp -d)
trap 'rm -rf "$w"' EXIT
a=(train --preset "$preset" --tasks CartPole,MountainCar --generations "$gens" --seed 7 --quiet)
"$mtpg" "${a[@]}" --out "$w/a" >/dev/null 2>&1
"$mtpg" "${a[@]}" --out "$w/b" >/dev/null 2>&1 &
pid=$!
until [ "$(cat "$w/b/metrics.csv" 2>/dev/null | wc -l)" -ge 14 ]; do sleep 0.05; done
t0=$(date +%s.%N)
kill -TERM $pid
status=0
wait $pid || status=$?
t1=$(date +%s.%N)
echo "exit status after SIGTERM: $status (143 expected); exited $(echo "$t1 - $t0" | bc) s after the signal"
"$mtpg" train --resume "$w/b" --quiet >/dev/null 2>&1
strip() { python3 -c "import csv,sys; r=list(csv.reader(open(sys.argv[1]))); k=[i for i,c in enumerate(r[0]) if not (c.startswith('t_') or 'per_s' in c)]; print([[x[i] for i in k] for x in r])" "$1"; }
if [ "$(strip "$w/a/metrics.csv")" = "$(strip "$w/b/metrics.csv")" ] && cmp -s "$w/a/tests.csv" "$w/b/tests.csv" \
  && diff -rq "$w/a/champions" "$w/b/champions" >/dev/null && diff -rq "$w/a/tests" "$w/b/tests" >/dev/null; then
  echo "resumed run identical to the uninterrupted one"
else
  echo "resumed run DIFFERS from the uninterrupted one"; exit 1
fi
