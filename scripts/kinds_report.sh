#!/usr/bin/env bash
# Report section 2b (accuracy per SDF kind, issue 20) on its own: sdfccd_bench kinds --baseline and
# kinds_front into OUTDIR (the data set from OUTDIR/dataset_kinds), then sdfccd_bench_report OUTDIR
# (every other section from the CSVs already there).
#   scripts/kinds_report.sh OUTDIR [--build BUILDDIR] [--before BENCH]
# --before BENCH: an sdfccd_bench built from an earlier commit; its FWGSS rows are added as FWGSS-before.
set -euo pipefail
out=${1:?usage: kinds_report.sh OUTDIR [--build BUILDDIR] [--before BENCH]}
shift
. "$(dirname "$0")/lib.sh"
report_options kinds_report.sh "--build --before" "$@"
bench="$build/samples/sdfccd_bench"
commit="$(commit_stamp)"
note="sdfccd_bench kinds --baseline and kinds_front, then sdfccd_bench_report (the other sections are from the earlier full run above); Load average at the start: $(cut -d' ' -f1-3 /proc/loadavg); the code of commit $commit"
"$bench" kinds --dataset "$out/dataset" --baseline > "$out/kinds.csv.tmp"
if [ -n "$before" ]; then
  "$before" kinds --dataset "$out/dataset" | awk -F, '$1 == "FWGSS" { sub(/^FWGSS,/, "FWGSS-before,"); print }' >> "$out/kinds.csv.tmp"
  note="$note; FWGSS-before: $before"
fi
mv "$out/kinds.csv.tmp" "$out/kinds.csv"
"$bench" kinds_front --dataset "$out/dataset" > "$out/kinds_front.csv.tmp"
mv "$out/kinds_front.csv.tmp" "$out/kinds_front.csv"
echo "$note; $(date -u '+%Y-%m-%d %H:%M UTC')" > "$out/kinds_machine.txt"
run_report "$out"
echo "report: $out/report.md" >&2
