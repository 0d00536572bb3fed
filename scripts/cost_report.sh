#!/usr/bin/env bash
# Report sections 4 (scaling) and 5 (cost per SDF evaluation) on their own: sdfccd_bench scaling
# --baseline and cost into OUTDIR, then sdfccd_bench_report over a copy of OUTDIR's CSVs, and the two
# sections replace theirs in OUTDIR/report.md (every other section, and section 9 pasted by
# scripts/grid_report.sh, stays as it is). --only scaling|cost runs that one experiment and replaces its
# section only (the other keeps its text and CSV).
#   scripts/cost_report.sh OUTDIR [--build BUILDDIR] [--only scaling|cost]
set -euo pipefail
out=${1:?usage: cost_report.sh OUTDIR [--build BUILDDIR] [--only scaling|cost]}
shift
. "$(dirname "$0")/lib.sh"
report_options cost_report.sh "--build --only" "$@"
case "$only" in
  "") exps="scaling cost chain"; ran="scaling --baseline, cost and chain"; from="4"; to="6" ;;
  scaling) exps="scaling"; ran="scaling --baseline"; from="4"; to="5" ;;
  cost) exps="cost chain"; ran="cost and chain"; from="5"; to="6" ;;
  *) echo "cost_report.sh: --only takes scaling or cost (got $only)" >&2; exit 2 ;;
esac
bench="$build/samples/sdfccd_bench"
commit="$(commit_stamp)"
note="sdfccd_bench $ran, then sdfccd_bench_report (scripts/cost_report.sh; the other sections are from earlier runs); Load average at the start: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) CPUs; the code of commit $commit"
for e in $exps; do
  echo "== sdfccd_bench $e --baseline" >&2
  "$bench" $e --dataset "$out/dataset" --baseline > "$out/$e.csv.tmp"
  mv "$out/$e.csv.tmp" "$out/$e.csv"
done
echo "$note; $(date -u '+%Y-%m-%d %H:%M UTC')" > "$out/cost_machine.txt"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$out"/*.csv "$out"/*.txt "$tmp"/
"$build/samples/sdfccd_bench_report" "$tmp"
# the fresh report's sections $from.. (up to "## $to.") replace the same lines in OUTDIR/report.md
awk -v a="^## $from\\. " -v b="^## $to\\. " '$0 ~ a {f=1} $0 ~ b {f=0} f' "$tmp/report.md" > "$tmp/sections.md"
awk -v s="$tmp/sections.md" -v a="^## $from\\. " -v b="^## $to\\. " '$0 ~ a {while ((getline l < s) > 0) print l; skip=1} $0 ~ b {skip=0} !skip' "$out/report.md" > "$tmp/report.new"
mv "$tmp/report.new" "$out/report.md"
echo "report: $out/report.md (sections $from to $((to - 1)))" >&2
