#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The evaluation report's speed-versus-accuracy chart (samples/report/report.md section 3,
`sdfccd_bench front`), recomputed from Python with sdfccd.run_cases and drawn with matplotlib.

On the first N cases of each mesh of the data set (samples/report/dataset: a triangle and the
888-triangle shuriken against a torus, certified ground truth in ground_truth.csv) it runs the same
sweep as the report: DCD, FW and the paper's FWGSS with the Frank-Wolfe cap 2..64 (twice as many
line-search iterations); today's FWGSS with restarts 0..2 and vertex trace 0..64; the three FWGSS
configurations (defaults, previous defaults, the paper's); certified with bracket widths
1e-3..1e-6 s. Subdivision off, as in the report. A miss (false negative) is no hit, or a TOI more
than 1 us after the certified bracket; a false positive a hit more than 1 us before it or where the
ground truth has none; |dTOI| is measured from the bracket (0 inside it). Times are wall clock
(run_cases' micros), so they vary with the machine's load; the report uses 512 cases per mesh.

    PYTHONPATH=build/python python3 python/examples/speed_accuracy.py [--cases N] [--out chart.png]
"""
import argparse
import csv
import os
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import sdfccd  # noqa: E402

TOI_TOL = 1e-6
ROOT = pathlib.Path(__file__).resolve().parents[2]


def sweep():
    """(method, setting, run_cases keyword arguments), in the report's order."""
    paper = dict(fwgss_secant_entry=0, fwgss_speed_tolerance=0, fwgss_clear_proof=0, fwgss_gap_tolerance=0.0,
                 fwgss_derivative_spatial=0, fwgss_restart_at_witness=0)
    out = []
    for name, method, extra in (("DCD", "dcd", {}), ("FW", "fw", {}),
                                ("FWGSS-paper", "fwgss", dict(paper, fwgss_vertex_trace=0, fwgss_restarts=0))):
        for cap in (2, 4, 8, 16, 32, 64):
            out.append((name, f"iter={cap} ls={2 * cap}", method,
                        dict(extra, max_iterations=cap, max_line_search_iterations=2 * cap)))
    for r in (0, 1, 2):
        for t in (0, 8, 16, 64):
            out.append(("FWGSS", f"restarts={r} trace={t}", "fwgss", dict(fwgss_restarts=r, fwgss_vertex_trace=t)))
    out.append(("FWGSS-defaults", "new", "fwgss", {}))
    out.append(("FWGSS-previous-defaults", "baseline", "fwgss", dict(paper)))
    out.append(("FWGSS-paper-config", "paper", "fwgss", dict(paper, fwgss_vertex_trace=0, fwgss_restarts=0)))
    for tol in (1e-3, 1e-4, 1e-5, 1e-6):
        out.append(("Certified", f"tol={tol:.0e}", "certified",
                    dict(certified_time_tolerance=tol, max_sdf_evaluations=5000000)))
    return out


def subset(dataset, n, folder):
    """A case file with the first n cases of each mesh (the records before the cases are kept)."""
    head, cases = [], {}
    with open(dataset / "cases.txt") as f:
        for line in f:
            tok = line.split()
            if tok and tok[0] == "case":
                mesh = tok[3]
                cases.setdefault(mesh, [])
                if len(cases[mesh]) < n:
                    cases[mesh].append(line)
            else:
                head.append(line.replace(" shuriken.obj", " " + str(dataset / "shuriken.obj")))
    path = pathlib.Path(folder) / "subset.cases"
    path.write_text("".join(head) + "".join(sum(cases.values(), [])))
    return path


def ground_truth(dataset):
    gt = {}
    with open(dataset / "ground_truth.csv") as f:
        rows = csv.DictReader(line for line in f if not line.startswith("#"))
        for r in rows:
            gt[r["id"]] = (int(r["hit"]), float(r["toi_lower"]), float(r["toi"]))
    return gt


def summarise(rows, gt):
    fn = fp = 0
    dt = []
    for r in rows:
        g_hit, g_lo, g_toi = gt[r["id"]]
        hit = r["hit"] == 1
        if g_hit and (not hit or r["toi"] > g_toi + TOI_TOL):
            fn += 1
        if hit and (not g_hit or r["toi"] < g_lo - TOI_TOL):
            fp += 1
        if g_hit and hit:
            d = r["toi"] - g_toi
            if d < 0 and r["toi"] >= g_lo:
                d = 0.0
            dt.append(abs(d))
    n = len(rows)
    return dict(mean_us=float(rows["micros"].mean()), fn_rate=fn / n, fp_rate=fp / n,
                mean_abs_dtoi=float(np.mean(dt)) if dt else 0.0, sdf_evals=float(rows["sdf_evals"].mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=64, help="cases per mesh (the report: 512)")
    ap.add_argument("--dataset", default=str(ROOT / "samples/report/dataset"))
    ap.add_argument("--out", default="speed_accuracy.png")
    args = ap.parse_args()
    dataset = pathlib.Path(args.dataset)
    gt = ground_truth(dataset)
    points = []
    with tempfile.TemporaryDirectory() as tmp:
        cases = subset(dataset, args.cases, tmp)
        for name, setting, method, extra in sweep():
            rows = sdfccd.run_cases(cases, method=method, params=dict(extra, subdivision=0))
            s = summarise(rows, gt)
            points.append((name, setting, s))
            print(f"{name:24s} {setting:20s} {s['mean_us']:9.1f} us  FN {s['fn_rate']:.4f}  FP {s['fp_rate']:.4f}  "
                  f"mean|dTOI| {s['mean_abs_dtoi']:.3g} s  evals {s['sdf_evals']:.0f}")
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.6))
    for ax, key, floor, label, title in ((axes[0], "fn_rate", 1e-4, "false-negative rate (floor 1e-4)", "speed vs misses"),
                                         (axes[1], "mean_abs_dtoi", 1e-10, "mean |dTOI| (s, floor 1e-10)",
                                          "speed vs TOI error")):
        for name in dict.fromkeys(p[0] for p in points):
            xs = [p[2]["mean_us"] for p in points if p[0] == name]
            ys = [max(p[2][key], floor) for p in points if p[0] == name]
            ax.plot(xs, ys, "o-", markersize=6, label=name)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_xlabel("mean time per query (us)")
        ax.set_ylabel(label)
        ax.set_title(f"{title} ({2 * args.cases} cases, sdfccd {sdfccd.__version__}, from Python)")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"chart: {os.path.abspath(args.out)}")


if __name__ == "__main__":
    main()
