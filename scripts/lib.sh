# Shared by the report scripts (source it): the repository root, the default build directory, the
# option parser and the commit stamp that every report records.
sdfccd_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$sdfccd_root/build"
before=""
mode=""
only=""

# report_options NAME ALLOWED ARGS...: sets build, before, mode and only from ARGS; an option not in
# ALLOWED (a space-separated list such as "--build --before") is an error naming script NAME.
report_options() {
  local name="$1" allowed=" $2 "
  shift 2
  while [ $# -gt 0 ]; do
    case "$allowed" in
      *" $1 "*) ;;
      *) echo "$name: unknown option $1" >&2; exit 2 ;;
    esac
    case "$1" in
      --build) build="$2"; shift ;;
      --before) before="$2"; shift ;;
      --only) only="$2"; shift ;;
      --quick|--smoke) mode="$1" ;;
    esac
    shift
  done
}

# commit_stamp: the short commit of the working tree, marked when tracked files differ from it.
commit_stamp() {
  local c
  c="$(git -C "$sdfccd_root" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)"
  if git -C "$sdfccd_root" status --porcelain --untracked-files=no 2>/dev/null | grep -q .; then
    c="$c (with uncommitted changes)"
  fi
  echo "$c"
}

# run_report OUTDIR: sdfccd_bench_report OUTDIR, keeping report section 9, which grid_report.sh pastes
# and the generator does not write (the report is otherwise made anew from OUTDIR's CSVs).
run_report() {
  local out="$1" kept
  kept="$(mktemp)"
  [ -f "$out/report.md" ] && awk '/^## 9\. /{f=1} f' "$out/report.md" > "$kept"
  "$build/samples/sdfccd_bench_report" "$out"
  if [ -s "$kept" ] && ! grep -q '^## 9\. ' "$out/report.md"; then
    printf '\n' >> "$out/report.md"
    cat "$kept" >> "$out/report.md"
  fi
  rm -f "$kept"
}
