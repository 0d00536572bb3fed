# SPDX-License-Identifier: MIT
# contact.h from Python (issue 19): the guard's safe pose against closed forms, contact generation
# for a resting and a falling cube against the cube's own corners, the reduction's deepest point,
# motions from poses, and bad input.
import gc
import math

import numpy as np
import pytest

import sdfccd

# contact.h is issue 19's (branch t19core): these tests run once the library has it.
pytestmark = pytest.mark.skipif(not sdfccd.HAVE_CONTACTS, reason="libsdfccd without contact.h")

H = 0.5
CUBE_V = np.array([[(H if i & 1 else -H), (H if i & 2 else -H), (H if i & 4 else -H)] for i in range(8)])
CUBE_T = np.array([0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7,
                   5], dtype=np.uint32).reshape(12, 3)


@pytest.fixture(autouse=True)
def no_leak():
    gc.collect()
    before = sdfccd.byte_count()
    yield
    gc.collect()
    assert sdfccd.byte_count() == before


@pytest.fixture
def scene():
    with sdfccd.half_space((0, 0, 1), 0.0) as ground, sdfccd.Mesh(CUBE_V, CUBE_T) as cube:
        yield ground, cube


def test_guard_rolls_back_to_the_closed_form_pose(scene):
    ground, cube = scene
    # The cube's bottom (z = c - 0.5) falls from c = 1 at 120 m/s: it reaches phi = -tol at
    # t = (0.5 + tol) / 120 s.
    tol = 5e-4
    executed = sdfccd.Motion(position=(0, 0, 1.0), velocity=(0, 0, -120.0))
    with sdfccd.Workspace() as ws:
        g = sdfccd.guard_rigid(ground, cube, executed, 0.0, 1.0 / 60.0, tolerance=tol, workspace=ws)
        assert g.state == "rolled_back"
        want = (0.5 + tol) / 120.0
        assert want - 1e-6 <= g.toi <= want + 1e-9
        assert abs(g.safe_position[2] - (1.0 - 120.0 * g.toi)) < 1e-12
        # The point is on the cube's bottom at the safe pose, no deeper than the tolerance.
        assert np.allclose(g.normal, (0, 0, 1)) and abs(g.point[2] - (g.safe_position[2] - H)) < 1e-12
        assert -tol - 1e-12 <= g.point[2] < 0.0
        away = sdfccd.Motion(position=(0, 0, 1.0), velocity=(0, 0, 30.0))
        clear = sdfccd.guard_rigid(ground, cube, away, workspace=ws)
        assert clear.state == "clear" and clear.toi == 1.0 / 60.0
        assert np.allclose(clear.safe_position, (0, 0, 1.5))
    # Linear: the cube's vertices sink from z >= 0.5 to z >= -1.5 over [0, 1].
    start, end = CUBE_V + (0, 0, 1.0), CUBE_V + (0, 0, -1.0)
    gl = sdfccd.guard_linear(ground, cube, start, end, 0.0, 1.0, tolerance=tol)
    assert gl.state == "rolled_back" and abs(gl.toi - (0.5 + tol) / 2.0) < 1e-6
    assert np.allclose(gl.positions, start + (end - start) * gl.toi, atol=1e-12)


def test_motion_from_poses():
    q = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # a quarter turn about z
    m = sdfccd.motion_from_poses((0, 0, 0), (1, 0, 0, 0), (1.0, 2.0, 3.0), q, 0.0, 0.5)
    c = m._c
    assert np.allclose(c.linear_velocity, (2.0, 4.0, 6.0))
    assert np.allclose(c.angular_velocity, (0, 0, math.pi))
    with pytest.raises(sdfccd.Error):
        sdfccd.motion_from_poses((0, 0, 0), (1, 0, 0, 0), (0, 0, 0), (2, 0, 0, 0), 0.0, 1.0)  # not unit
    with pytest.raises(sdfccd.Error):
        sdfccd.motion_from_poses((0, 0, 0), (1, 0, 0, 0), (0, 0, 0), (1, 0, 0, 0), 1.0, 1.0)  # t1 <= t0


def test_generated_contacts_are_the_cube_corners(scene):
    ground, cube = scene
    resting = sdfccd.Motion(position=(0, 0, H))
    pts, info = sdfccd.generate_contacts(ground, cube, resting, capacity=4)
    assert info["count"] == 4 and info["started_in_contact"]
    bottom = CUBE_V[CUBE_V[:, 2] < 0] + (0, 0, H)
    for p in bottom:  # every bottom corner is one of the four points
        assert np.min(np.linalg.norm(pts["point"] - p, axis=1)) < 1e-9
    assert np.allclose(pts["normal"], (0, 0, 1)) and np.allclose(pts["gap"], 0.0, atol=1e-12)
    # Falling from 0.3 m above at 60 m/s: the CCD's time of impact 0.3 / 60 s, gaps 0.3 m at t0.
    falling = sdfccd.Motion(position=(0, 0, H + 0.3), velocity=(0, 0, -60.0))
    pts, info = sdfccd.generate_contacts(ground, cube, falling, capacity=4)
    assert info["ccd_ran"] and abs(info["toi"] - 0.3 / 60.0) < 1e-7
    assert len(pts) == 4 and np.allclose(pts["gap"], 0.3, atol=1e-6)
    # Linear version of the same fall.
    pts_l, info_l = sdfccd.generate_contacts_linear(ground, cube, CUBE_V + (0, 0, H + 0.3),
                                                    CUBE_V + (0, 0, H + 0.3 - 1.0), 0.0, 1.0 / 60.0)
    assert abs(info_l["toi"] - 0.3 / 60.0) < 1e-7 and len(pts_l) == 4


def test_reduction_keeps_the_deepest(scene):
    ground, cube = scene
    rng = np.random.default_rng(5)
    pts = np.zeros(200, dtype=sdfccd.CONTACT_POINT_DTYPE)
    pts["point"][:, :2] = rng.uniform(-1, 1, (200, 2))
    pts["surface_point"] = pts["point"]
    pts["normal"] = (0, 0, 1)
    pts["gap"] = rng.uniform(0.0, 1e-3, 200)
    pts["gap"][137] = -0.01
    pts["id"] = np.arange(200)
    idx = sdfccd.reduce_contacts(pts, 4)
    assert len(idx) == 4 and len(set(idx)) == 4 and 137 in idx
    assert len(sdfccd.reduce_contacts(pts[:2], 4)) == 2
    with pytest.raises(TypeError):
        sdfccd.reduce_contacts(np.zeros((4, 3)), 4)
    with pytest.raises(sdfccd.Error):
        sdfccd.reduce_contacts(pts, 4, same_place_distance=-1.0)


def test_guard_world_rolls_back_the_falling_body(scene):
    # Two cubes over the ground: one falling from c = 1 at 120 m/s, which goes back to where its bottom
    # was half the tolerance deep, t = (0.5 + tol / 2) / 120 s, and loses its velocity into the ground;
    # one moving up, left at its end pose.
    ground, cube = scene
    tol, dt = 5e-4, 1.0 / 60.0
    q = (1.0, 0.0, 0.0, 0.0)
    big = 1e9
    sdfs = [{"sdf": ground, "start": ((0, 0, 0), q), "start_box": ((-big, -big, -big), (big, big, 0.0)), "friction": 0.5}]

    def body(z0, z1):
        r = math.sqrt(3) * H
        return {"start": ((0, 0, z0), q), "end": ((0, 0, z1), q), "reach": r,
                "start_box": ((-r, -r, z0 - r), (r, r, z0 + r)), "end_box": ((-r, -r, z1 - r), (r, r, z1 + r)),
                "parts": [(cube, ((0, 0, 0), q))], "friction": 0.5,
                "state": {"center": (0, 0, z1), "linear_velocity": (0, 0, (z1 - z0) / dt), "inverse_mass": 1.0,
                          "inverse_inertia": np.eye(3)}}

    with sdfccd.Workspace() as ws:
        fall, up = sdfccd.guard_world(sdfs, [body(1.0, -1.0), body(0.6, 1.1)], 0.0, dt, tolerance=tol, workspace=ws)
    want = (0.5 + 0.5 * tol) / 120.0
    assert fall["rolled_back"] and fall["sdf"] == 0 and fall["part"] == 0 and fall["queries"] == 1
    assert want - 0.1 * tol / 120.0 <= fall["guard"].toi <= want + 1e-12
    assert abs(fall["position"][2] - (1.0 - 120.0 * fall["guard"].toi)) < 1e-12
    assert abs(fall["linear_velocity"][2]) < 1e-9 and fall["sdf_evaluations"] > 0
    assert not up["rolled_back"] and up["sdf"] == -1 and np.allclose(up["position"], (0, 0, 1.1))
    assert up["linear_velocity"][2] == pytest.approx(30.0)
    # Bad input: an SDF's body index out of range, a NaN pose.
    with pytest.raises(sdfccd.Error):
        sdfccd.guard_world([dict(sdfs[0], body=5)], [body(1.0, -1.0)])
    with pytest.raises(ValueError):
        sdfccd.guard_world(sdfs, [body(1.0, float("nan"))])


def test_bad_input(scene):
    ground, cube = scene
    m = sdfccd.Motion(position=(0, 0, 1.0), velocity=(0, 0, -120.0))
    with pytest.raises(sdfccd.Error):
        sdfccd.guard_rigid(ground, cube, m, tolerance=-1.0)
    with pytest.raises(sdfccd.Error):
        sdfccd.guard_rigid(ground, cube, m, method="dcd")
    with pytest.raises(ValueError):
        sdfccd.guard_linear(ground, cube, CUBE_V[:4], CUBE_V[:4])
    with pytest.raises(TypeError):
        sdfccd.generate_contacts(ground, cube, m, workspace="ws")
    with pytest.raises(sdfccd.Error):
        sdfccd.generate_contacts(ground, cube, m, vertex_distance=-1.0)
    ws = sdfccd.Workspace()
    ws.close()
    ws.close()
    with pytest.raises(sdfccd.Error):
        sdfccd.guard_rigid(ground, cube, m, workspace=ws)
    closed = sdfccd.Mesh(CUBE_V, CUBE_T)
    closed.close()
    with pytest.raises(sdfccd.Error):
        sdfccd.generate_contacts(ground, closed, m)


def test_queries_through_a_workspace_equal_the_plain_ones():
    # A box field has gradient jumps, so FWGSS's answer is checked by the certified search, whose scratch
    # is the workspace's when one is given (sdfccd_query_*_ws): the same answers, evaluations and contacts.
    tri = np.array([[-0.05, -0.03, 0.0], [0.05, -0.03, 0.0], [0.0, 0.06, 0.0]])
    rng = np.random.default_rng(5)
    hits = 0
    with sdfccd.box((0.1, 0.06, 0.03)) as field, sdfccd.Mesh(CUBE_V * 0.1, CUBE_T) as cube, sdfccd.Workspace() as ws:
        for _ in range(6):
            d = rng.normal(size=3)
            d /= np.linalg.norm(d)
            m = sdfccd.Motion(position=0.25 * d, velocity=-0.25 * d * 60.0 / rng.uniform(0.6, 1.2),
                              angular_velocity=rng.normal(size=3) * 20.0)
            for fn, target in ((sdfccd.query_triangle, tri), (sdfccd.query_mesh, cube)):
                plain = fn(field, target, m)
                reused = fn(field, target, m, workspace=ws)
                assert (plain.state, plain.hit, plain.toi, plain.sdf_evaluations) == \
                    (reused.state, reused.hit, reused.toi, reused.sdf_evaluations)
                assert plain.contacts.tobytes() == reused.contacts.tobytes()
                hits += plain.hit
            start, end = tri + 0.2 * d, tri - 0.2 * d
            plain = sdfccd.query_triangle_linear(field, start, end)
            reused = sdfccd.query_triangle_linear(field, start, end, workspace=ws)
            assert (plain.toi, plain.sdf_evaluations) == (reused.toi, reused.sdf_evaluations)
            ends = (CUBE_V * 0.1 + 0.2 * d, CUBE_V * 0.1 - 0.2 * d)
            plain = sdfccd.query_mesh_linear(field, cube, *ends)
            reused = sdfccd.query_mesh_linear(field, cube, *ends, workspace=ws)
            assert (plain.toi, plain.sdf_evaluations) == (reused.toi, reused.sdf_evaluations)
        with pytest.raises(TypeError):
            sdfccd.query_triangle(field, tri, workspace="scratch")
    assert hits >= 4
