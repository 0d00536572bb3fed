#!/usr/bin/env bash
# Report sections 4 (scaling) and 5 (cost per SDF evaluation) on their own: sdfccd_bench scaling
# --baseline and cost into OUTDIR, then sdfccd_bench_report over a copy of OUTDIR's CSVs, and the two
# sections replace theirs in OUTDIR/report.md (every other section, and section 9 pasted by
# scripts/grid_report.sh, stays as it is).
#   scripts/cost_report.sh OUTDIR [--build BUILDDIR]
set -euo pipefail
out=${1:?usage: cost_report.sh OUTDIR [--build BUILDDIR]}
shift
. "$(dirname "$0")/lib.sh"
report_options cost_report.sh "--build" "$@"
bench="$build/samples/sdfccd_bench"
commit="$(commit_stamp)"
note="sdfccd_bench scaling --baseline and cost, then sdfccd_bench_report (scripts/cost_report.sh; the other sections are from earlier runs); Load average at the start: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) CPUs; the code of commit $commit"
for e in scaling cost; do
  echo "== sdfccd_bench $e --baseline" >&2
  "$bench" $e --dataset "$out/dataset" --baseline > "$out/$e.csv.tmp"
  mv "$out/$e.csv.tmp" "$out/$e.csv"
done
echo "$note; $(date -u '+%Y-%m-%d %H:%M UTC')" > "$out/cost_machine.txt"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$out"/*.csv "$out"/*.txt "$tmp"/
"$build/samples/sdfccd_bench_report" "$tmp"
# sections 4 and 5 of the fresh report replace the lines from "## 4." up to "## 6." in OUTDIR/report.md
awk '/^## 4\. /{f=1} /^## 6\. /{f=0} f' "$tmp/report.md" > "$tmp/sections.md"
awk -v s="$tmp/sections.md" '/^## 4\. /{while ((getline l < s) > 0) print l; skip=1} /^## 6\. /{skip=0} !skip' "$out/report.md" > "$tmp/report.new"
mv "$tmp/report.new" "$out/report.md"
echo "report: $out/report.md (sections 4 and 5)" >&2
