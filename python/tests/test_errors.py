# SPDX-License-Identifier: MIT
# Every bad input raises (TypeError / ValueError in Python, sdfccd.Error with the library's message
# from the library), never crashes, and leaves no library memory behind.
import gc

import numpy as np
import pytest

import sdfccd

TRI = np.array([[0.0, 0.0, 0.0], [-0.02, 0.01, 0.0], [-0.02, -0.01, 0.005]])


@pytest.fixture(autouse=True)
def no_leak():
    gc.collect()
    before = sdfccd.byte_count()
    yield
    gc.collect()
    assert sdfccd.byte_count() == before


def test_library_errors_carry_the_message():
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.sphere(-1.0)
    assert e.value.status == "SDFCCD_INVALID_ARGUMENT" and "radius" in e.value.message
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.torus(0.05, 0.1)
    assert e.value.status == "SDFCCD_INVALID_ARGUMENT"
    with sdfccd.sphere(0.1) as s:
        with pytest.raises(sdfccd.Error) as e:
            sdfccd.query_triangle(s, TRI, None, 1.0, 0.0)  # t1 < t0
        assert e.value.status == "SDFCCD_INVALID_ARGUMENT"
        with pytest.raises(sdfccd.Error):
            s.save("/tmp/never.cdf")  # not a grid
        with pytest.raises(sdfccd.Error):
            s.grid_info()
        with pytest.raises(sdfccd.Error) as e:
            sdfccd.query_triangle(s, [[0, 0, 0], [1, 0, 0], [2, 0, 0]])  # zero area
        assert e.value.status == "SDFCCD_DEGENERATE"
        with pytest.raises(sdfccd.Error):
            sdfccd.query_triangle(s, TRI, params={"max_line_search_iterations": 0})


def test_wrong_dtypes_shapes_and_non_finite_values():
    with sdfccd.sphere(0.1) as s:
        for bad, exc in ((TRI.astype(np.float32), TypeError), (TRI.astype(np.int64), TypeError),
                         (TRI[:2], ValueError), (TRI.ravel(), ValueError), ([["a", 0, 0]] * 3, TypeError),
                         (np.where(TRI == 0, np.nan, TRI), ValueError), (np.full((3, 3), np.inf), ValueError)):
            with pytest.raises(exc):
                sdfccd.query_triangle(s, bad)
        with pytest.raises(TypeError):
            s.eval(np.zeros((4, 3), dtype=np.float32))
        with pytest.raises(ValueError):
            s.eval(np.zeros((4, 2)))
        with pytest.raises(ValueError):
            s.eval([np.nan, 0, 0])
        with pytest.raises(ValueError):
            sdfccd.Motion(position=(np.nan, 0, 0))
        with pytest.raises(ValueError):
            sdfccd.Motion(orientation=(1, 0, 0))
        with pytest.raises(TypeError):
            sdfccd.query_triangle(s, TRI, motion="fast")
        with pytest.raises(ValueError):
            sdfccd.query_triangle(s, TRI, t1=np.inf)
        with pytest.raises(TypeError):
            sdfccd.query_triangle("sphere", TRI)
        with pytest.raises(ValueError):
            sdfccd.query_triangle(s, TRI, method="newton")
        with pytest.raises(TypeError):
            sdfccd.query_triangle(s, TRI, params={"no_such_field": 1})
        with pytest.raises(TypeError):
            sdfccd.query_triangle(s, TRI, params={"margin": "1"})
        with pytest.raises(ValueError):
            sdfccd.query_triangle(s, TRI, max_contacts=-1)
        with pytest.raises(TypeError):
            sdfccd.union(s, "box")
        with pytest.raises(ValueError):
            sdfccd.box((1, 1))
        with pytest.raises(TypeError):
            sdfccd.sphere("1")
        with pytest.raises(ValueError):
            sdfccd.sphere(float("nan"))
        with pytest.raises(ValueError):
            sdfccd.extract_isosurface(s, (0, 0), (1, 1, 1))
        with pytest.raises(sdfccd.Error):
            sdfccd.extract_isosurface(s, (1, 1, 1), (0, 0, 0), 8)


def test_batch_inputs():
    with sdfccd.sphere(0.1) as s:
        tri = np.repeat(TRI[None], 4, 0)
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri, threads=0)
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri, threads=257)
        with pytest.raises(TypeError):
            sdfccd.query_batch(s, tri, motions=np.zeros((4, 16)))
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri, motions=sdfccd.motions(3))
        mo = sdfccd.motions(4)
        mo["linear_velocity"][2, 0] = np.nan
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri, motions=mo)
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri[:, :2])
        with pytest.raises(ValueError):
            sdfccd.query_batch(s, tri, triangles_end=tri[:3])
        with pytest.raises(ValueError):
            sdfccd.query_batch(s)
        bad = tri.copy()
        bad[3] = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]
        with pytest.raises(sdfccd.Error) as e:
            sdfccd.query_batch(s, bad, threads=2)
        assert e.value.status == "SDFCCD_DEGENERATE"
        with pytest.raises(TypeError):
            sdfccd.query_batch(s, meshes=["mesh"])
        res, con = sdfccd.query_batch(s, np.zeros((0, 3, 3)))
        assert len(res) == 0


def test_closed_handles_raise():
    s = sdfccd.sphere(0.1)
    m = sdfccd.Mesh(TRI, [[0, 1, 2]])
    s.close()
    m.close()
    with pytest.raises(sdfccd.Error) as e:
        s.eval([0, 0, 0])
    assert e.value.status == "SDFCCD_INVALID_HANDLE"
    for call in (lambda: sdfccd.query_triangle(s, TRI), lambda: sdfccd.union(s, s), lambda: s.info(),
                 lambda: sdfccd.transformed(s), lambda: m.info(), lambda: m.arrays(),
                 lambda: sdfccd.grid_from_mesh(m), lambda: sdfccd.grid_from_sdf(s), lambda: sdfccd.query_batch(s, TRI[None])):
        with pytest.raises(sdfccd.Error):
            call()
    with sdfccd.half_space((0, 0, 1), 0) as g:
        with pytest.raises(sdfccd.Error):
            sdfccd.query_mesh(g, m)


def test_meshes_and_files(tmp_path, source_dir):
    with pytest.raises(TypeError):
        sdfccd.Mesh(TRI, [[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError):
        sdfccd.Mesh(TRI, [[0, 1, 3]])
    with pytest.raises(ValueError):
        sdfccd.Mesh(TRI, [[0, 1, -1]])
    with pytest.raises(ValueError):
        sdfccd.Mesh(TRI, [0, 1, 2])
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]])
    assert e.value.status == "SDFCCD_DEGENERATE"
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.load_mesh(tmp_path / "none.obj")
    assert e.value.status == "SDFCCD_IO_ERROR"
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.load_mesh(tmp_path / "bad.obj")
    assert e.value.status == "SDFCCD_FORMAT_ERROR"
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.load_mesh(source_dir / "data/bullet3/cube.obj", formats="stl")
    assert e.value.status == "SDFCCD_UNSUPPORTED"
    (tmp_path / "bad.cdf").write_bytes(b"\x01\x02garbage")
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.load_grid(tmp_path / "bad.cdf")
    assert e.value.status == "SDFCCD_FORMAT_ERROR"
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.load_grid(tmp_path / "none.cdf")
    assert e.value.status == "SDFCCD_IO_ERROR"
    with pytest.raises(TypeError):
        sdfccd.load_grid(3)


class Boom(Exception):
    pass


def test_callback_exceptions_are_reported_not_crashes():
    def bad(p):
        raise Boom("inside the SDF")

    with sdfccd.callback(bad) as cb:
        with pytest.raises(sdfccd.CallbackError) as e:
            sdfccd.query_triangle(cb, TRI, sdfccd.Motion(position=(-0.3, 0, 0), velocity=(36, 0, 0)))
        assert isinstance(e.value.__cause__, Boom)
        with pytest.raises(sdfccd.CallbackError):
            cb.eval([0, 0, 0])
        with sdfccd.union(cb, sdfccd.sphere(0.1)) as u:  # inside a combination, on two threads
            with pytest.raises(sdfccd.CallbackError):
                sdfccd.query_batch(u, np.repeat(TRI[None], 4, 0), threads=2)
    with sdfccd.callback(lambda p: (0.0, (1.0, 2.0))) as cb:  # a gradient of the wrong shape
        with pytest.raises(sdfccd.CallbackError):
            cb.eval([0, 0, 0])
    with sdfccd.callback(lambda p: "far") as cb:
        with pytest.raises(sdfccd.CallbackError):
            cb.eval([0, 0, 0])
    with pytest.raises(TypeError):
        sdfccd.callback(42)
    with pytest.raises(sdfccd.Error):
        sdfccd.callback(lambda p: 0.0, lipschitz=-1.0)


def test_progress_callback_cancel_and_exception(source_dir):
    box = source_dir / "data/discregrid/box.obj"
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.grid_from_mesh(box, resolution=8, threads=1, progress=lambda f: True)
    assert e.value.status == "SDFCCD_CANCELLED"

    def bad(f):
        raise Boom("in progress")

    with pytest.raises(sdfccd.CallbackError) as e:
        sdfccd.grid_from_mesh(box, resolution=8, threads=1, progress=bad)
    assert isinstance(e.value.__cause__, Boom)
    with pytest.raises(TypeError):
        sdfccd.grid_from_mesh(box, progress=3)
    with pytest.raises(TypeError):
        sdfccd.grid_from_mesh(42)
    with pytest.raises(sdfccd.Error):
        sdfccd.grid_from_mesh(box, resolution=0)
    with pytest.raises(ValueError):
        sdfccd.grid_from_mesh(box, resolution=(8, 8))


@pytest.mark.skipif(sdfccd.HAVE_CONTACTS, reason="the library has contact.h")
def test_contact_functions_without_contact_h_raise():
    with pytest.raises(sdfccd.Error) as e:
        sdfccd.Workspace()
    assert e.value.status == "SDFCCD_UNSUPPORTED"
    with pytest.raises(sdfccd.Error):
        sdfccd.reduce_contacts(np.zeros(0, dtype=sdfccd.CONTACT_POINT_DTYPE), 4)
