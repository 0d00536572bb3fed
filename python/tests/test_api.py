# SPDX-License-Identifier: MIT
# The package's coverage: SDFs (analytic, CSG, transformed, Python callables, grids), meshes,
# queries (triangle, linear, mesh, batch), isosurfaces, and the README's C example in Python.
# References are closed forms, the C program itself, or the single queries (for the batch).
import gc
import re
import subprocess

import numpy as np
import pytest

import sdfccd


@pytest.fixture(autouse=True)
def no_leak():
    gc.collect()
    before = sdfccd.byte_count()
    yield
    gc.collect()
    assert sdfccd.byte_count() == before


def test_version():
    assert re.fullmatch(r"\d+\.\d+\.\d+", sdfccd.__version__)
    from sdfccd import _libpath
    assert _libpath.VERSION == sdfccd.__version__


def test_readme_example_in_python_gives_the_same_numbers(readme_example):
    out = subprocess.run([str(readme_example)], capture_output=True, text=True)
    assert out.returncode == 0
    with sdfccd.torus(0.10, 0.05) as torus:
        tri = np.array([[0.0, 0.0, 0.0], [-0.02, 0.01, 0.0], [-0.02, -0.01, 0.005]])
        motion = sdfccd.Motion(position=(-0.30, 0.0, 0.0), velocity=(36.0, 0.0, 0.0))
        r = sdfccd.query_triangle(torus, tri, motion, 0.0, 1.0 / 60.0, max_contacts=8)
    c = r.contacts[0]
    line = "first impact at t = %.7f s at (%.4f, %.4f, %.4f), normal (%.3f, %.3f, %.3f)\n" % (
        r.toi, *c["point"], *c["normal"])
    assert r.hit and abs(r.toi - 0.15 / 36.0) < 1e-6
    assert line == out.stdout


def test_readme_python_block_runs(source_dir):
    text = (source_dir / "README.md").read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    scope = {}
    exec(compile(block, "README.md", "exec"), scope)
    assert scope["r"].hit and abs(scope["r"].toi - 0.15 / 36.0) < 1e-6


def test_python_threads_share_handles():
    import threading
    tri, mo = random_queries(32, 11)
    with sdfccd.torus(0.1, 0.05) as torus:
        want = [sdfccd.query_triangle(torus, tri[i], motion_of(mo[i])).toi for i in range(len(tri))]
        got = {}

        def worker(k):
            got[k] = [sdfccd.query_triangle(torus, tri[i], motion_of(mo[i])).toi for i in range(len(tri))]

        threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert all(got[k] == want for k in range(4))


def test_analytic_csg_and_transformed_values():
    rng = np.random.default_rng(1)
    p = rng.uniform(-0.3, 0.3, (200, 3))
    with sdfccd.sphere(0.1) as s, sdfccd.box((0.2, 0.05, 0.05)) as b:
        ds = np.linalg.norm(p, axis=1) - 0.1
        q = np.abs(p) - (0.2, 0.05, 0.05)
        db = np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
        np.testing.assert_allclose(s(p), ds, atol=1e-15)
        np.testing.assert_allclose(b(p), db, atol=1e-15)
        with sdfccd.union(s, b) as u, sdfccd.intersection(s, b) as i, sdfccd.difference(s, b) as d:
            np.testing.assert_allclose(u(p), np.minimum(ds, db), atol=1e-15)
            np.testing.assert_allclose(i(p), np.maximum(ds, db), atol=1e-15)
            np.testing.assert_allclose(d(p), np.maximum(ds, -db), atol=1e-15)
        # A quarter turn about z maps the box's x extent to y; scale 2 doubles distances.
        h = np.sqrt(0.5)
        with sdfccd.transformed(b, (0.1, 0, 0), (h, 0, 0, h), 2.0) as t:
            local = (p - (0.1, 0, 0)) @ np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]]).T / 2.0
            q = np.abs(local) - (0.2, 0.05, 0.05)
            want = 2.0 * (np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0))
            np.testing.assert_allclose(t(p), want, atol=1e-12)
            assert t.info()["kind"] == "transform"
        value, grad = s.eval([0.3, 0.0, 0.0])
        assert value == pytest.approx(0.2) and np.allclose(grad, (1, 0, 0))
    # Children closed before their combination: it keeps them alive.
    a, b2 = sdfccd.sphere(0.1), sdfccd.sphere(0.2)
    u = sdfccd.union(a, b2)
    a.close()
    b2.close()
    assert u([0.0, 0.0, 0.5]) == pytest.approx(0.3)
    u.close()
    for kind, s in (("torus", sdfccd.torus(0.1, 0.05)), ("capsule", sdfccd.capsule(0.1, 0.05)),
                    ("cylinder", sdfccd.cylinder(0.1, 0.05)), ("half_space", sdfccd.half_space((0, 0, 1), 0.0)),
                    ("rounded_box", sdfccd.rounded_box((0.1, 0.1, 0.1), 0.02)), ("spike_grid", sdfccd.spike_grid())):
        with s:
            assert s.info()["kind"] == kind


def sphere_fn(p):
    n = np.linalg.norm(p)
    return n - 0.1, p / n


def test_python_callable_sdf_matches_the_analytic_sphere():
    tri = np.array([[0.0, 0.0, 0.0], [-0.02, 0.01, 0.0], [-0.02, -0.01, 0.005]])
    m = sdfccd.Motion(position=(-0.30, 0.0, 0.0), velocity=(36.0, 0.0, 0.0))
    with sdfccd.sphere(0.1) as s, sdfccd.callback(sphere_fn, bounds=((-0.1,) * 3, (0.1,) * 3)) as cb, \
            sdfccd.callback(lambda p: np.linalg.norm(p) - 0.1) as cb_fd:
        rs = sdfccd.query_triangle(s, tri, m)
        rc = sdfccd.query_triangle(cb, tri, m)
        rd = sdfccd.query_triangle(cb_fd, tri, m)
        assert rs.hit and rc.hit and rd.hit
        assert abs(rc.toi - 0.2 / 36.0) < 1e-6 and abs(rs.toi - rc.toi) < 1e-9 and abs(rd.toi - rc.toi) < 1e-6
        v, g = cb.eval([[0.2, 0, 0]])
        assert v[0] == pytest.approx(0.1) and np.allclose(g[0], (1, 0, 0))
        # Batch on two threads calls the Python function from the library's threads.
        res, _ = sdfccd.query_batch(cb, np.repeat(tri[None], 4, 0), m, threads=2)
        assert (res["toi"] == rc.toi).all()


def test_meshes_and_mesh_queries(source_dir):
    with sdfccd.load_mesh(source_dir / "data/discregrid/box.obj") as mesh, \
            sdfccd.half_space((0, 0, 1), 0.0) as ground:
        v, t = mesh.arrays()
        info = mesh.info()
        assert v.shape == (info["vertex_count"], 3) and t.shape == (info["triangle_count"], 3)
        assert t.dtype == np.uint32 and t.max() < len(v)
        zmin = v[:, 2].min()
        # Falling from z = 1 at 30 m/s: the lowest vertex reaches z = 0 at (1 + zmin) / 30.
        m = sdfccd.Motion(position=(0, 0, 1.0), velocity=(0, 0, -30.0))
        r = sdfccd.query_mesh(ground, mesh, m, 0.0, 1.0 / 20.0)
        assert r.hit and abs(r.toi - (1.0 + zmin) / 30.0) < 1e-6
        assert len(r.contacts) >= 1 and np.allclose(r.contacts["normal"], (0, 0, 1))
        start = v + (0, 0, 1.0)
        end = v + (0, 0, 1.0 - 30.0 / 20.0)
        rl = sdfccd.query_mesh_linear(ground, mesh, start, end, 0.0, 1.0 / 20.0)
        assert abs(rl.toi - r.toi) < 1e-6
        with sdfccd.Mesh(v, t) as copy:
            assert np.array_equal(copy.vertices, v) and np.array_equal(copy.indices, t)
    # One triangle, linear vertices.
    with sdfccd.half_space((0, 0, 1), 0.0) as ground:
        a = np.array([[0, 0, 1.0], [1, 0, 1.0], [0, 1, 0.5]])
        b = a - (0, 0, 1.0)
        r = sdfccd.query_triangle_linear(ground, a, b, 0.0, 1.0)
        assert abs(r.toi - 0.5) < 1e-7 and r.state == "hit"


def random_queries(n, seed):
    rng = np.random.default_rng(seed)
    tri = rng.uniform(-0.03, 0.03, (n, 3, 3))
    mo = sdfccd.motions(n)
    mo["position"] = rng.uniform(-0.3, 0.3, (n, 3))
    mo["linear_velocity"] = -mo["position"] * 60 * rng.uniform(0.5, 2.0, (n, 1))
    mo["angular_velocity"] = rng.uniform(-60, 60, (n, 3))
    return tri, mo


def motion_of(rec):
    return sdfccd.Motion(rec["position"], rec["orientation"], rec["linear_velocity"], rec["angular_velocity"],
                         rec["local_center"])


def same_result(batch_row, batch_contacts, single):
    assert batch_row["state"] == sdfccd.STATES.index(single.state)
    assert batch_row["hit"] == single.hit
    for f in ("toi", "fraction", "toi_lower"):
        assert np.float64(batch_row[f]).tobytes() == np.float64(getattr(single, f)).tobytes()
    for f in ("sdf_evaluations", "iterations", "triangles_tested", "contacts_found"):
        assert batch_row[f] == getattr(single, f)
    assert batch_contacts[: batch_row["contact_count"]].tobytes() == single.contacts.tobytes()


def test_batch_on_two_threads_equals_single_queries():
    tri, mo = random_queries(96, 7)
    with sdfccd.torus(0.1, 0.05) as torus, sdfccd.box((0.1, 0.1, 0.02)) as b, sdfccd.difference(torus, b) as csg:
        for sdf in (torus, csg):
            res, con = sdfccd.query_batch(sdf, tri, mo, threads=2, max_contacts=8)
            assert res["hit"].sum() > 20
            for i in range(len(tri)):
                same_result(res[i], con[i], sdfccd.query_triangle(sdf, tri[i], motion_of(mo[i]), max_contacts=8))
            res1, con1 = sdfccd.query_batch(sdf, tri, mo, threads=1, max_contacts=8)
            assert res1.tobytes() == res.tobytes() and con1.tobytes() == con.tobytes()
        # Linear triangles and rigid meshes.
        end = tri + mo["linear_velocity"][:, None, :] / 60.0 + mo["position"][:, None, :]
        start = tri + mo["position"][:, None, :]
        res, con = sdfccd.query_batch(torus, start, triangles_end=end, threads=2)
        for i in range(len(tri)):
            same_result(res[i], con[i], sdfccd.query_triangle_linear(torus, start[i], end[i], max_contacts=8))
        meshes = [sdfccd.Mesh(tri[i], [[0, 1, 2]]) for i in range(8)]
        res, con = sdfccd.query_batch(torus, meshes=meshes, motions=mo[:8], threads=2)
        for i in range(8):
            same_result(res[i], con[i], sdfccd.query_mesh(torus, meshes[i], motion_of(mo[i]), max_contacts=8))
        for m in meshes:
            m.close()


def test_grid_bake_progress_save_load(source_dir, tmp_path):
    fractions = []
    with sdfccd.grid_from_mesh(source_dir / "data/discregrid/box.obj", resolution=8, threads=1,
                               progress=lambda f: fractions.append(f)) as g:
        assert fractions and fractions[-1] == 1.0 and fractions == sorted(fractions)
        info = g.grid_info()
        assert info["resolution"] == (8, 8, 8)
        g.save(tmp_path / "box.cdf")
        with sdfccd.load_grid(tmp_path / "box.cdf") as h:
            lo, hi = info["domain"]
            p = np.random.default_rng(3).uniform(lo, hi, (100, 3))
            assert g(p).tobytes() == h(p).tobytes()
            assert h.info()["kind"] == "grid"
    with sdfccd.sphere(0.1) as s, sdfccd.grid_from_sdf(s, resolution=16, padding=0.05) as g:
        p = np.random.default_rng(4).uniform(-0.1, 0.1, (50, 3))
        np.testing.assert_allclose(g(p), s(p), atol=2e-3)


def test_isosurface():
    with sdfccd.sphere(0.1) as s:
        v, t = sdfccd.extract_isosurface(s, (-0.15,) * 3, (0.15,) * 3, 24)
    assert v.dtype == np.float64 and t.dtype == np.uint32 and v.shape[1] == 3 and t.shape[1] == 3
    assert len(t) > 100 and t.max() < len(v)
    assert np.abs(np.linalg.norm(v, axis=1) - 0.1).max() < 0.3 / 24


def test_handles_freed_by_gc_and_context_managers():
    gc.collect()
    before = sdfccd.byte_count()
    for _ in range(50):
        sdfccd.union(sdfccd.sphere(0.1), sdfccd.box((1, 1, 1)))
    gc.collect()
    assert sdfccd.byte_count() == before
    s = sdfccd.sphere(0.1)
    with s:
        pass
    assert s.closed
    s.close()  # twice: nothing
    cb = sdfccd.callback(sphere_fn)
    u = sdfccd.union(cb, sdfccd.sphere(0.05))
    del cb
    gc.collect()
    assert u([0.3, 0, 0]) == pytest.approx(0.2)  # the callback outlives its own handle
    u.close()
