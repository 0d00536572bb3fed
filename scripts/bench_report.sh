#!/usr/bin/env bash
# The evaluation report: runs every sdfccd_bench experiment into OUTDIR/NAME.csv, then
# sdfccd_bench_report OUTDIR writes OUTDIR/report.md (and the chart, with gnuplot).
#   scripts/bench_report.sh OUTDIR [--quick|--smoke] [--build BUILDDIR] [--only "name ..."]
# The data set and its certified ground truth are read from OUTDIR/dataset when present (copy
# samples/report/dataset there to skip the ~4 minutes of ground truth), else computed there; the data
# set per SDF kind likewise from OUTDIR/dataset_kinds (samples/report/dataset_kinds; ~6 minutes of
# ground truth, most of it on the two grids).
# Every experiment interleaves the previous FWGSS defaults (--baseline) so ratios come from one run.
set -euo pipefail
out=${1:?usage: bench_report.sh OUTDIR [--quick|--smoke] [--build BUILDDIR] [--only "names"]}
shift
. "$(dirname "$0")/lib.sh"
only="dataset brute accuracy kinds kinds_front front targets scaling batch cost"
report_options bench_report.sh "--quick --smoke --build --only" "$@"
bench="$build/samples/sdfccd_bench"
mkdir -p "$out"
# The commit line first: writing machine.txt below would itself count as an uncommitted change
# when OUTDIR is the committed samples/report.
commit="$(commit_stamp)"
{
  echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //'), $(nproc) logical CPUs, $(uname -sr); shared with other users: compare ratios from one run"
  echo "Load average at the start: $(cut -d" " -f1-3 /proc/loadavg) (on $(nproc) CPUs); above the CPU count, timings are contended: trust SDF-evaluation counts and same-run ratios"
  echo "Commit: $commit; date $(date -u '+%Y-%m-%d %H:%M UTC'); mode ${mode:-full}"
} > "$out/machine.txt"
for e in $only; do
  echo "== sdfccd_bench $e $mode --baseline" >&2
  "$bench" "$e" --dataset "$out/dataset" $mode --baseline > "$out/$e.csv.tmp"
  mv "$out/$e.csv.tmp" "$out/$e.csv"
done
run_report "$out"
echo "report: $out/report.md" >&2
