# SPDX-License-Identifier: MIT
# sdfccd.run_cases against the C runner (sdfccd_cases): the same rows bit for bit and the same
# errors. Every column but `micros` (a wall-clock timing, never reproducible) is compared: ids and
# states as strings, hits and counts as integers, floats by their bits (the CSV prints %.17g, which
# round-trips a double exactly; an empty field is NaN in the array).
import subprocess

import numpy as np
import pytest

import sdfccd

COMPARED = [c for c in sdfccd.CASES_COLUMNS if c != "micros"]
FLOATS = ("toi", "x", "y", "z", "nx", "ny", "nz")


def run_cli(exe, path, *args):
    return subprocess.run([str(exe), *args, str(path)], capture_output=True, text=True)


def parse_csv(text):
    lines = text.splitlines()
    assert lines[0] == ",".join(sdfccd.CASES_COLUMNS)
    return [line.split(",") for line in lines[1:]]


def assert_same(rows, csv_rows):
    assert len(rows) == len(csv_rows)
    assert rows.dtype.names == sdfccd.CASES_COLUMNS
    for r, c in zip(rows, csv_rows):
        rec = dict(zip(sdfccd.CASES_COLUMNS, c))
        assert r["id"] == rec["id"]
        assert r["hit"] == int(rec["hit"])
        assert r["state"] == rec["state"]
        for f in FLOATS:
            want = float(rec[f]) if rec[f] != "" else np.nan
            assert np.float64(want).tobytes() == np.float64(r[f]).tobytes(), (rec["id"], f, rec[f], r[f])
        assert r["triangles_tested"] == int(rec["triangles_tested"])
        assert r["sdf_evals"] == int(rec["sdf_evals"])


@pytest.mark.parametrize("method,args", [("fwgss", []), ("dcd", ["--method", "dcd"]),
                                         ("fwgss", ["--no-subdivision", "--margin", "0.001"])])
def test_data_set_equals_the_c_runner(cases_exe, source_dir, method, args):
    path = source_dir / "samples/report/dataset/cases.txt"
    cli = run_cli(cases_exe, path, *args)
    assert cli.returncode == 0, cli.stderr
    kw = {}
    if "--no-subdivision" in args:
        kw = {"subdivision": False, "margin": 0.001}
    rows = sdfccd.run_cases(path, method=method, **kw)
    assert len(rows) == 2048
    assert_same(rows, parse_csv(cli.stdout))
    # The data set is on collision courses (DCD sees only the end pose: about half).
    assert (rows["hit"] == 1).sum() > (2000 if method == "fwgss" else 500)


def test_certified_and_states_on_the_example(cases_exe, source_dir):
    path = source_dir / "data/cases/example.cases"
    for method in ("certified", "fw", "fwgss"):
        cli = run_cli(cases_exe, path, "--method", method)
        assert cli.returncode == 0, cli.stderr
        assert_same(sdfccd.run_cases(path, method=method), parse_csv(cli.stdout))


def test_budget_state(cases_exe, source_dir, tmp_path):
    # An evaluation budget of 5 stops every query that needs more: state "budget" in both.
    path = source_dir / "data/cases/example.cases"
    rows = sdfccd.run_cases(path, params={"max_sdf_evaluations": 5})
    assert (rows["state"] == "budget").sum() >= 5
    normal = sdfccd.run_cases(path)
    assert "budget" not in set(normal["state"])


MALFORMED = {
    "no_header.cases": "sdf t torus 0.1 0.05\n",
    "empty.cases": "# nothing\n",
    "bad_version.cases": "sdfccd-cases 2\n",
    "unknown_record.cases": "sdfccd-cases 1\nfoo bar\n",
    "unknown_kind.cases": "sdfccd-cases 1\nsdf t cone 1\n",
    "bad_number.cases": "sdfccd-cases 1\nsdf t sphere 1x\n",
    "nan_number.cases": "sdfccd-cases 1\nsdf t sphere nan\n",
    "negative_radius.cases": "sdfccd-cases 1\nsdf t sphere -1\n",
    "duplicate.cases": "sdfccd-cases 1\nsdf t sphere 1\nsdf t sphere 2\n",
    "unknown_sdf.cases": "sdfccd-cases 1\nmesh m triangle 0 0 0 1 0 0 0 1 0\ncase c nope m 0.1 0 0 1 1 0 0 0 0 0 0 0 0 0\n",
    "unknown_mesh.cases": "sdfccd-cases 1\nsdf s sphere 0.1\ncase c s nope 0.1 0 0 1 1 0 0 0 0 0 0 0 0 0\n",
    "few_fields.cases": "sdfccd-cases 1\nsdf s sphere 0.1\nmesh m triangle 0 0 0 1 0 0 0 1 0\ncase c s m 0.1 0 0 1\n",
    "negative_dt.cases": "sdfccd-cases 1\nsdf s sphere 0.1\nmesh m triangle 0 0 0 1 0 0 0 1 0\n"
                         "case c s m -1 0 0 1 1 0 0 0 0 0 0 0 0 0\n",
    "zero_quat.cases": "sdfccd-cases 1\nsdf s sphere 0.1\nmesh m triangle 0 0 0 1 0 0 0 1 0\n"
                       "case ok s m 0.1 0 0 1 1 0 0 0 0 0 -10 0 0 0\ncase c s m 0.1 0 0 1 0 0 0 0 0 0 0 0 0 0\n",
    "degenerate.cases": "sdfccd-cases 1\nmesh m triangle 0 0 0 1 0 0 2 0 0\n",
    "missing_grid.cases": "sdfccd-cases 1\nsdf g grid no_such.cdf\n",
    "missing_mesh_file.cases": "sdfccd-cases 1\nmesh m file no_such.obj\n",
    "too_many_tokens.cases": "sdfccd-cases 1\n" + "x " * 40 + "\n",
    "long_line.cases": "sdfccd-cases 1\n# " + "a" * 20000 + "\n",
}


@pytest.mark.parametrize("name", sorted(MALFORMED))
def test_malformed_files_give_the_c_runners_error(cases_exe, tmp_path, name):
    path = tmp_path / name
    path.write_text(MALFORMED[name])
    cli = run_cli(cases_exe, path)
    assert cli.returncode == 1
    assert cli.stderr.startswith("sdfccd_cases: ")
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.run_cases(path)
    assert e.value.message == cli.stderr[len("sdfccd_cases: "):].rstrip("\n")
    assert f"{name}:" in e.value.message


def test_missing_file_and_bad_arguments(cases_exe, tmp_path):
    path = tmp_path / "absent.cases"
    cli = run_cli(cases_exe, path)
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.run_cases(path)
    assert e.value.status == "SDFCCD_IO_ERROR"
    assert e.value.message == cli.stderr[len("sdfccd_cases: "):].rstrip("\n")
    with pytest.raises(ValueError):
        sdfccd.run_cases(path, method="newton")
    with pytest.raises(TypeError):
        sdfccd.run_cases(42)
    with pytest.raises(ValueError):
        sdfccd.run_cases(path, margin=float("nan"))
