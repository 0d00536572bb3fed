# SPDX-License-Identifier: MIT
"""sdfccd: continuous collision detection between moving triangles and signed distance fields.

Python bindings of libsdfccd's C ABI through ctypes (no compiled extension). Units are metres and
seconds; phi < 0 inside. Arrays are numpy float64 (points, vertices: shape (N, 3)) and uint32
(triangle indices: shape (T, 3)); C-contiguous float64 arrays are passed to the library without a
copy, lists are converted, arrays of another dtype raise TypeError.

Errors: a failing library call raises :class:`Error` (its ``status`` name and the library's message,
``sdfccd_last_error()``); bad Python input raises TypeError or ValueError before the library sees
it. Handles (:class:`Sdf`, :class:`Mesh`) are freed by ``close()``, a ``with`` block or garbage
collection, exactly once; using a closed handle raises :class:`Error`.

Threads: every call releases the GIL while the library runs (ctypes), the library is thread-safe
(queries on shared handles from several Python threads are fine) and :func:`query_batch` runs its
queries on ``threads`` native threads. Python-callable SDFs (:func:`callback`) take the GIL for each
evaluation: correct from any thread, but serial and slow (microseconds per evaluation, a query
needs hundreds to thousands).
"""
import ctypes as C
import math
import os
import threading

import numpy as np

from . import _lib
from ._lib import lib as _L

__all__ = [
    "Error", "CallbackError", "Sdf", "Mesh", "Motion", "QueryResult", "params", "sphere", "box", "rounded_box",
    "torus", "capsule", "cylinder", "half_space", "spike_grid", "union", "intersection", "difference",
    "transformed", "callback", "load_grid", "grid_from_mesh", "grid_from_sdf", "load_mesh", "query_triangle",
    "query_triangle_linear", "query_mesh", "query_mesh_linear", "query_batch", "extract_isosurface", "run_cases",
    "byte_count", "Workspace", "motion_from_poses", "guard_rigid", "guard_linear", "guard_world", "GuardResult", "generate_contacts",
    "generate_contacts_linear", "reduce_contacts", "CONTACT_POINT_DTYPE", "HAVE_CONTACTS", "CONTACT_DTYPE", "RESULT_DTYPE", "MOTION_DTYPE", "CASES_DTYPE", "CASES_COLUMNS", "library_path",
]

__version__ = _L.sdfccd_version_string().decode()
try:
    from . import _libpath as _lp
    if getattr(_lp, "VERSION", __version__) != __version__:
        raise ImportError(f"sdfccd: the package is version {_lp.VERSION} but {_lib.library_path} is {__version__}")
except ModuleNotFoundError:
    pass
configuration = _L.sdfccd_configuration_string().decode()
library_path = _lib.library_path

#: numpy dtypes with the C layouts: arrays of them go to the library without a copy.
CONTACT_DTYPE = np.dtype(_lib.Contact)
RESULT_DTYPE = np.dtype(_lib.QueryResult)
MOTION_DTYPE = np.dtype(_lib.RigidMotion)

METHODS = {"fwgss": 0, "fw": 1, "dcd": 2, "certified": 3}
STATES = ("no_hit", "hit", "penetrating", "not_converged")
_CSG = {"union": 0, "intersection": 1, "difference": 2}


class Error(RuntimeError):
    """A library call failed: ``status`` (e.g. "SDFCCD_INVALID_ARGUMENT") and the library's message."""

    def __init__(self, status, message):
        self.status = status
        self.message = message
        super().__init__(f"{status}: {message}")


class CallbackError(Error):
    """A Python callable (SDF, progress) raised; the original exception is ``__cause__``."""


def _status_name(st):
    return _L.sdfccd_status_string(st).decode()


def _check(st):
    if st != 0:
        raise Error(_status_name(st), _L.sdfccd_last_error().decode(errors="replace"))


def byte_count():
    """Bytes the library holds (0 once every handle is closed)."""
    return _L.sdfccd_byte_count()


# ---------------------------------------------------------------------------------------------
# input checks

def _float_array(a, name, shape):
    """A C-contiguous float64 array of `shape` (-1 = any length) with finite values; no copy when `a`
    already is one. Arrays of another dtype raise TypeError (lists and tuples are converted)."""
    if isinstance(a, np.ndarray):
        if a.dtype != np.float64:
            raise TypeError(f"{name}: expected a float64 array, got {a.dtype}")
    else:
        try:
            a = np.asarray(a, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise TypeError(f"{name}: expected numbers: {e}") from None
    if a.ndim != len(shape) or any(s != -1 and s != d for s, d in zip(shape, a.shape)):
        want = "(" + ", ".join("N" if s == -1 else str(s) for s in shape) + ")"
        raise ValueError(f"{name}: expected shape {want}, got {a.shape}")
    a = np.ascontiguousarray(a)
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: contains a non-finite value")
    return a


def _vec3(v, name):
    a = _float_array(v, name, (3,))
    return _lib.Vec3(*a)


def _scalar(v, name):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(v).__name__}")
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"{name}: not finite ({v})")
    return v


def _int(v, name):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {type(v).__name__}")
    return int(v)


def _path(p, name="path"):
    if not isinstance(p, (str, bytes, os.PathLike)):
        raise TypeError(f"{name}: expected a path, got {type(p).__name__}")
    return os.fsencode(p)


# ---------------------------------------------------------------------------------------------
# handles

class _Handle:
    _id = None

    def __init__(self, hid, deps=()):
        self._id = hid
        self._deps = tuple(deps)  # Python objects the library object uses (callbacks must outlive it)
        self._lock = threading.Lock()

    @property
    def closed(self):
        return self._id is None

    def _handle(self):
        hid = self._id
        if hid is None:
            raise Error("SDFCCD_INVALID_HANDLE", f"{type(self).__name__} is closed")
        return hid

    def close(self):
        """Releases the handle (once; later calls do nothing). Combinations using it stay valid."""
        with self._lock:
            hid, self._id = self._id, None
        if hid is not None:
            self._destroy(hid)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_id", None) is not None:
            try:
                self.close()
            except Exception:
                pass


class Sdf(_Handle):
    """A signed distance field handle (analytic, CSG, transformed, callback or grid)."""

    _destroy = staticmethod(_L.sdfccd_destroy_sdf)

    def eval(self, points):
        """phi and its gradient at points (N, 3) -> (values (N,), gradients (N, 3)); a single point
        (3,) gives (float, (3,))."""
        single = np.ndim(points) == 1
        p = _float_array(points, "points", (3,) if single else (-1, 3))
        p2 = p.reshape(-1, 3)
        n = p2.shape[0]
        if n > 2**31 - 1:
            raise ValueError("points: too many")
        values = np.empty(n)
        grads = np.empty((n, 3))
        st = _L.sdfccd_sdf_eval_batch(self._handle(), p2.ctypes.data, n, values.ctypes.data, grads.ctypes.data)
        _raise_callback_errors(self)
        _check(st)
        if single:
            return float(values[0]), grads[0]
        return values, grads

    def __call__(self, points):
        """phi at points (N, 3) -> (N,), or at one point -> float."""
        return self.eval(points)[0]

    def info(self):
        """kind, domain, bounds, lipschitz and memory_bytes, as a dict."""
        info = _lib.SdfInfo()
        _check(_L.sdfccd_sdf_get_info(self._handle(), C.byref(info)))
        kinds = ("sphere", "box", "rounded_box", "torus", "capsule", "cylinder", "half_space", "spike_grid", "csg",
                 "transform", "callback", "grid")
        return {
            "kind": kinds[info.kind] if 0 <= info.kind < len(kinds) else info.kind,
            "domain": (np.array(info.domain.lo), np.array(info.domain.hi)),
            "bounds": (np.array(info.bounds.lo), np.array(info.bounds.hi)),
            "lipschitz": info.lipschitz,
            "memory_bytes": info.memory_bytes,
        }

    def save(self, path):
        """Writes a grid SDF as a Discregrid `.cdf` file."""
        _check(_L.sdfccd_save_grid(self._handle(), _path(path)))

    def grid_info(self):
        """Resolution, domain, cell size and storage of a grid SDF, as a dict."""
        g = _lib.GridInfo()
        _check(_L.sdfccd_grid_get_info(self._handle(), C.byref(g)))
        return {
            "resolution": tuple(g.resolution), "domain": (np.array(g.domain.lo), np.array(g.domain.hi)),
            "cell_size": np.array(g.cell_size), "field_count": g.field_count, "cell_count": g.cell_count,
            "stored_cells": g.stored_cells, "valued_cells": g.valued_cells, "node_count": g.node_count,
            "memory_bytes": g.memory_bytes, "file_bytes": g.file_bytes, "max_lipschitz": g.max_lipschitz,
            "band": g.band,
        }


class Mesh(_Handle):
    """A triangle mesh handle: vertices (V, 3) in its local frame, counter-clockwise triangles (T, 3)."""

    _destroy = staticmethod(_L.sdfccd_destroy_mesh)

    def __init__(self, vertices, indices, drop_degenerate=False):
        v = _float_array(vertices, "vertices", (-1, 3))
        idx = _index_array(indices, v.shape[0])
        d = _L.sdfccd_default_mesh_def()
        d.vertices = v.ctypes.data
        d.vertex_count = v.shape[0]
        d.indices = idx.ctypes.data
        d.triangle_count = idx.shape[0]
        d.drop_degenerate = 1 if drop_degenerate else 0
        mid = _lib.MeshId()
        _check(_L.sdfccd_create_mesh(C.byref(d), C.byref(mid)))
        super().__init__(mid)

    @classmethod
    def _wrap(cls, mid):
        m = cls.__new__(cls)
        _Handle.__init__(m, mid)
        return m

    def info(self):
        i = _lib.MeshInfo()
        _check(_L.sdfccd_mesh_get_info(self._handle(), C.byref(i)))
        return {"vertex_count": i.vertex_count, "triangle_count": i.triangle_count,
                "dropped_triangles": i.dropped_triangles, "bounds": (np.array(i.bounds.lo), np.array(i.bounds.hi)),
                "memory_bytes": i.memory_bytes}

    def arrays(self):
        """(vertices (V, 3) float64, indices (T, 3) uint32): copies of the mesh's data."""
        info = self.info()
        v = np.empty((info["vertex_count"], 3))
        t = np.empty((info["triangle_count"], 3), dtype=np.uint32)
        _check(_L.sdfccd_mesh_get_data(self._handle(), v.ctypes.data, t.ctypes.data))
        return v, t

    @property
    def vertices(self):
        return self.arrays()[0]

    @property
    def indices(self):
        return self.arrays()[1]


def _index_array(indices, vertex_count):
    if isinstance(indices, np.ndarray):
        if not np.issubdtype(indices.dtype, np.integer):
            raise TypeError(f"indices: expected an integer array, got {indices.dtype}")
        a = indices
    else:
        a = np.asarray(indices)
        if a.size and not np.issubdtype(a.dtype, np.integer):
            raise TypeError(f"indices: expected integers, got {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"indices: expected shape (T, 3), got {a.shape}")
    if a.size and (a.min() < 0 or a.max() >= vertex_count):
        raise ValueError(f"indices: out of range [0, {vertex_count})")
    return np.ascontiguousarray(a, dtype=np.uint32)


def load_mesh(path, scale=1.0, merge_vertices=True, drop_degenerate=True, formats=None, max_file_bytes=None):
    """Loads a mesh file (OBJ by the library's own reader, other formats through assimp)."""
    d = _L.sdfccd_default_mesh_load_def()
    d.scale = _scalar(scale, "scale")
    d.merge_vertices = 1 if merge_vertices else 0
    d.drop_degenerate = 1 if drop_degenerate else 0
    if formats is not None:
        if not isinstance(formats, str):
            raise TypeError("formats: expected a string such as 'obj;stl'")
        d.formats = formats.encode()
    if max_file_bytes is not None:
        d.max_file_bytes = _int(max_file_bytes, "max_file_bytes")
    mid = _lib.MeshId()
    _check(_L.sdfccd_load_mesh(_path(path), C.byref(d), C.byref(mid)))
    return Mesh._wrap(mid)


# ---------------------------------------------------------------------------------------------
# SDF constructors

def _new_sdf(fn, *args, deps=()):
    sid = _lib.SdfId()
    _check(fn(*args, C.byref(sid)))
    return Sdf(sid, deps)


def sphere(radius):
    return _new_sdf(_L.sdfccd_create_sphere, _scalar(radius, "radius"))


def box(half_extents):
    return _new_sdf(_L.sdfccd_create_box, _vec3(half_extents, "half_extents"))


def rounded_box(half_extents, radius):
    return _new_sdf(_L.sdfccd_create_rounded_box, _vec3(half_extents, "half_extents"), _scalar(radius, "radius"))


def torus(major, minor):
    return _new_sdf(_L.sdfccd_create_torus, _scalar(major, "major"), _scalar(minor, "minor"))


def capsule(half_height, radius):
    return _new_sdf(_L.sdfccd_create_capsule, _scalar(half_height, "half_height"), _scalar(radius, "radius"))


def cylinder(half_height, radius):
    return _new_sdf(_L.sdfccd_create_cylinder, _scalar(half_height, "half_height"), _scalar(radius, "radius"))


def half_space(normal, offset):
    return _new_sdf(_L.sdfccd_create_half_space, _vec3(normal, "normal"), _scalar(offset, "offset"))


def spike_grid(spacing=None, base_radius=None, height=None, count_x=None, count_y=None):
    """The paper's spike grid (defaults of sdfccd_default_spike_grid_def for unset arguments)."""
    d = _L.sdfccd_default_spike_grid_def()
    for name, v in (("spacing", spacing), ("base_radius", base_radius), ("height", height)):
        if v is not None:
            setattr(d, name, _scalar(v, name))
    for name, v in (("count_x", count_x), ("count_y", count_y)):
        if v is not None:
            setattr(d, name, _int(v, name))
    return _new_sdf(_L.sdfccd_create_spike_grid, C.byref(d))


def _sdf_arg(s, name):
    if not isinstance(s, Sdf):
        raise TypeError(f"{name}: expected an sdfccd.Sdf, got {type(s).__name__}")
    return s._handle()


def _csg(op, a, b):
    return _new_sdf(_L.sdfccd_create_csg, _CSG[op], _sdf_arg(a, "a"), _sdf_arg(b, "b"), deps=(a, b))


def union(a, b):
    """min(a, b)."""
    return _csg("union", a, b)


def intersection(a, b):
    """max(a, b)."""
    return _csg("intersection", a, b)


def difference(a, b):
    """a minus b: max(a, -b)."""
    return _csg("difference", a, b)


def transformed(child, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0), scale=1.0):
    """`child` placed at `position` with the unit quaternion `orientation` (w, x, y, z), uniformly scaled."""
    pose = _lib.Pose()
    pose.position[:] = _float_array(position, "position", (3,))
    pose.orientation[:] = _float_array(orientation, "orientation", (4,))
    return _new_sdf(_L.sdfccd_create_transformed, _sdf_arg(child, "child"), pose, _scalar(scale, "scale"),
                    deps=(child,))


class _PyCallback:
    """The C thunk of a Python SDF. An exception in the callable is kept (the first one) and the
    evaluation returns NaN with gradient (0, 0, 1); every later evaluation returns NaN at once, and
    the call that evaluated it raises CallbackError (see _raise_callback_errors)."""

    def __init__(self, fn, gradient_step):
        self.fn = fn
        self.h = gradient_step
        self.errors = []
        self.lock = threading.Lock()
        self.thunk = _lib.EvalFcn(self._eval)

    def _value_grad(self, p, want_grad):
        r = self.fn(p)
        if isinstance(r, tuple):
            value, grad = r
            return float(value), (np.asarray(grad, dtype=np.float64) if want_grad else None)
        value = float(r)
        if not want_grad:
            return value, None
        g = np.empty(3)
        for k in range(3):
            e = np.zeros(3)
            e[k] = self.h
            g[k] = (float(self.fn(p + e)) - float(self.fn(p - e))) / (2 * self.h)
        return value, g

    def _eval(self, p, grad_ptr, user):
        if self.errors:
            return math.nan
        try:
            value, g = self._value_grad(np.array((p.x, p.y, p.z)), bool(grad_ptr))
            if grad_ptr:
                if g.shape != (3,):
                    raise ValueError(f"SDF callback: gradient of shape {g.shape}, expected (3,)")
                grad_ptr[0].x, grad_ptr[0].y, grad_ptr[0].z = float(g[0]), float(g[1]), float(g[2])
            return value
        except BaseException as e:  # never let an exception unwind through C
            with self.lock:
                self.errors.append(e)
            return math.nan


def callback(fn, lipschitz=1.0, bounds=None, gradient_step=1e-6, smooth=False):
    """An SDF evaluated by the Python callable ``fn(p) -> phi`` or ``-> (phi, gradient)`` for a point
    p (numpy (3,)). Without a gradient it is taken by central differences (6 more calls). Slow: a
    few microseconds of Python per evaluation; the library calls it from its own threads too (with
    the GIL). If ``fn`` raises, the calls that evaluated it raise :class:`CallbackError` from that
    exception, and the SDF keeps failing. ``bounds`` = (lo, hi) contains every point with phi <= 0.
    ``smooth``: the gradient is continuous outside the surface (sdfccd_CallbackSdfDef.smooth)."""
    if not callable(fn):
        raise TypeError("fn: expected a callable")
    cb = _PyCallback(fn, _scalar(gradient_step, "gradient_step"))
    d = _L.sdfccd_default_callback_sdf_def()
    d.eval = cb.thunk
    d.lipschitz = _scalar(lipschitz, "lipschitz")
    d.smooth = 1 if smooth else 0
    if bounds is not None:
        lo, hi = bounds
        d.bounds.lo[:] = _float_array(lo, "bounds[0]", (3,))
        d.bounds.hi[:] = _float_array(hi, "bounds[1]", (3,))
    s = _new_sdf(_L.sdfccd_create_callback_sdf, C.byref(d), deps=(cb,))
    return s


def _callbacks_of(obj, seen=None):
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, _PyCallback):
        yield obj
    for d in getattr(obj, "_deps", ()):
        yield from _callbacks_of(d, seen)


def _raise_callback_errors(*objs):
    for o in objs:
        for cb in _callbacks_of(o):
            if cb.errors:
                e = cb.errors[0]
                raise CallbackError("SDFCCD_CALLBACK", f"the Python SDF callback raised {type(e).__name__}: {e}") from e


# ---------------------------------------------------------------------------------------------
# grids

class _Progress:
    def __init__(self, fn):
        self.fn = fn
        self.error = None
        self.thunk = _lib.ProgressFcn(self._call)

    def _call(self, fraction, user):
        try:
            return 1 if self.fn(fraction) else 0
        except BaseException as e:
            self.error = e
            return 1  # cancels the build


def _grid_def(resolution, domain, padding, band, threads, invert, allow_open_mesh, max_bytes, progress):
    d = _L.sdfccd_default_grid_def()
    if isinstance(resolution, (int, np.integer)) and not isinstance(resolution, bool):
        resolution = (resolution,) * 3
    if len(resolution) != 3:
        raise ValueError("resolution: an integer or three")
    d.resolution[:] = [_int(r, "resolution") for r in resolution]
    if domain is not None:
        d.fit_domain = 0
        d.domain.lo[:] = _float_array(domain[0], "domain[0]", (3,))
        d.domain.hi[:] = _float_array(domain[1], "domain[1]", (3,))
    d.padding = _scalar(padding, "padding")
    d.band = _scalar(band, "band")
    d.threads = _int(threads, "threads")
    d.invert = 1 if invert else 0
    d.allow_open_mesh = 1 if allow_open_mesh else 0
    if max_bytes is not None:
        d.max_bytes = _int(max_bytes, "max_bytes")
    prog = None
    if progress is not None:
        if not callable(progress):
            raise TypeError("progress: expected a callable")
        prog = _Progress(progress)
        d.progress = prog.thunk
    return d, prog


def _build_grid(fn, source, d, prog):
    sid = _lib.SdfId()
    st = fn(source, C.byref(d), C.byref(sid))
    if prog is not None and prog.error is not None:
        raise CallbackError("SDFCCD_CANCELLED", f"the progress callback raised {type(prog.error).__name__}: "
                            f"{prog.error}") from prog.error
    _check(st)
    return Sdf(sid)


def grid_from_mesh(mesh, resolution=32, domain=None, padding=0.0, band=0.0, threads=0, invert=False,
                   allow_open_mesh=False, max_bytes=None, progress=None):
    """Bakes a mesh's exact signed distance into a grid SDF (Discregrid's layout). ``mesh``: a Mesh or
    a mesh file path. ``progress(fraction)`` is called from this thread; return True to cancel."""
    if isinstance(mesh, (str, bytes, os.PathLike)):
        with load_mesh(mesh) as m:
            return grid_from_mesh(m, resolution, domain, padding, band, threads, invert, allow_open_mesh, max_bytes,
                                  progress)
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh: expected an sdfccd.Mesh or a path, got {type(mesh).__name__}")
    d, prog = _grid_def(resolution, domain, padding, band, threads, invert, allow_open_mesh, max_bytes, progress)
    return _build_grid(_L.sdfccd_create_grid_from_mesh, mesh._handle(), d, prog)


def grid_from_sdf(sdf, resolution=32, domain=None, padding=0.0, band=0.0, threads=0, invert=False, max_bytes=None,
                  progress=None):
    """Samples any SDF into a grid SDF (its bounds must be finite unless a domain is given)."""
    d, prog = _grid_def(resolution, domain, padding, band, threads, invert, False, max_bytes, progress)
    g = _build_grid(_L.sdfccd_create_grid_from_sdf, _sdf_arg(sdf, "sdf"), d, prog)
    try:
        _raise_callback_errors(sdf)
    except CallbackError:
        g.close()
        raise
    return g


def load_grid(path):
    """Loads a Discregrid `.cdf` file as a grid SDF."""
    return _new_sdf(_L.sdfccd_load_grid, _path(path))


# ---------------------------------------------------------------------------------------------
# queries

class Motion:
    """A rigid motion (the paper's Eq. 14): pose at t0 (`position`, unit quaternion `orientation`
    w, x, y, z), `velocity` of the centre `center` (local frame), world `angular_velocity` (rad/s)."""

    def __init__(self, position=(0.0, 0.0, 0.0), orientation=(1.0, 0.0, 0.0, 0.0), velocity=(0.0, 0.0, 0.0),
                 angular_velocity=(0.0, 0.0, 0.0), center=(0.0, 0.0, 0.0)):
        m = _lib.RigidMotion()
        m.position[:] = _float_array(position, "position", (3,))
        m.orientation[:] = _float_array(orientation, "orientation", (4,))
        m.linear_velocity[:] = _float_array(velocity, "velocity", (3,))
        m.angular_velocity[:] = _float_array(angular_velocity, "angular_velocity", (3,))
        m.local_center[:] = _float_array(center, "center", (3,))
        self._c = m

    def as_record(self):
        """This motion as a MOTION_DTYPE scalar record."""
        return np.frombuffer(bytes(self._c), dtype=MOTION_DTYPE)[0]


def motions(n):
    """n identity motions (MOTION_DTYPE, orientation (1, 0, 0, 0)) to fill for query_batch."""
    a = np.zeros(_int(n, "n"), dtype=MOTION_DTYPE)
    a["orientation"][:, 0] = 1.0
    return a


def _motion_arg(m, name, allow_none):
    if m is None:
        if allow_none:
            return None
        return Motion()._c
    if isinstance(m, Motion):
        return m._c
    raise TypeError(f"{name}: expected an sdfccd.Motion, got {type(m).__name__}")


def params(method="fwgss", **fields):
    """sdfccd_default_query_params() with `method` ("fwgss", "fw", "dcd", "certified") and any other
    field of sdfccd_QueryParams set by name (e.g. margin=0.001, subdivision=0)."""
    p = _L.sdfccd_default_query_params()
    if method not in METHODS:
        raise ValueError(f"method: one of {sorted(METHODS)}, got {method!r}")
    p.method = METHODS[method]
    names = {f[0]: f[1] for f in _lib.QueryParams._fields_}
    for k, v in fields.items():
        if k not in names or k in ("method", "internal_value"):
            raise TypeError(f"params: unknown field {k!r}")
        if names[k] is C.c_double:
            setattr(p, k, _scalar(v, k))
        else:
            v = int(v) if isinstance(v, (bool, np.bool_)) else _int(v, k)
            setattr(p, k, v)
    return p


def _params_arg(p, method):
    if p is None:
        return params(method)
    if isinstance(p, dict):
        return params(method, **p)
    if isinstance(p, _lib.QueryParams):
        return p
    raise TypeError("params: expected None, a dict of fields or sdfccd.params(...)")


class QueryResult:
    """The summary of a query and its contacts (a CONTACT_DTYPE array: point, normal, distance,
    gap_t0, toi, barycentric, triangle, kind)."""

    def __init__(self, r, contacts):
        self.state = STATES[r.state] if 0 <= r.state < len(STATES) else r.state
        self.hit = bool(r.hit)
        self.toi = r.toi
        self.fraction = r.fraction
        self.toi_lower = r.toi_lower
        self.contacts = contacts[: r.contact_count]
        self.contacts_found = r.contacts_found
        self.iterations = r.iterations
        self.sdf_evaluations = r.sdf_evaluations
        self.triangles_tested = r.triangles_tested

    def __repr__(self):
        return (f"QueryResult(state={self.state!r}, hit={self.hit}, toi={self.toi!r}, contacts={len(self.contacts)}, "
                f"sdf_evaluations={self.sdf_evaluations})")


def _capacity(max_contacts):
    n = _int(max_contacts, "max_contacts")
    if n < 0 or n > 1 << 20:
        raise ValueError("max_contacts: in [0, 2^20]")
    return n


def _run_query(name, sdf, args, t0, t1, p, max_contacts, sdf_motion, workspace):
    """Calls sdfccd_<name>, or sdfccd_<name>_ws with the workspace's scratch when one is given."""
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    cap = _capacity(max_contacts)
    contacts = np.zeros(cap, dtype=CONTACT_DTYPE)
    res = _lib.QueryResult()
    rest = (_sdf_arg(sdf, "sdf"), C.byref(sm) if sm is not None else None, *args, _scalar(t0, "t0"), _scalar(t1, "t1"),
            C.byref(p), contacts.ctypes.data if cap else None, cap, C.byref(res))
    if workspace is None:
        st = getattr(_L, "sdfccd_" + name)(*rest)
    else:
        _need_contacts()
        st = _with_workspace(workspace, lambda ws: getattr(_L, "sdfccd_" + name + "_ws")(ws, *rest))
    _raise_callback_errors(sdf)
    _check(st)
    return QueryResult(res, contacts)


def query_triangle(sdf, triangle, motion=None, t0=0.0, t1=1.0 / 60.0, params=None, method="fwgss", sdf_motion=None,
                   max_contacts=16, workspace=None):
    """First time of impact of one triangle (3, 3) (local frame) under a rigid Motion against `sdf`
    (static at the origin, or moving with `sdf_motion`). With a Workspace, its scratch is reused: after
    the first query nothing is allocated (sdfccd_query_triangle_ws)."""
    tri = _float_array(triangle, "triangle", (3, 3))
    m = _motion_arg(motion, "motion", False)
    return _run_query("query_triangle", sdf, (tri.ctypes.data, C.byref(m)), t0, t1, _params_arg(params, method),
                      max_contacts, sdf_motion, workspace)


def query_triangle_linear(sdf, start, end, t0=0.0, t1=1.0 / 60.0, params=None, method="fwgss", sdf_motion=None,
                          max_contacts=16, workspace=None):
    """One triangle whose world vertices move linearly from `start` (3, 3) at t0 to `end` at t1 (`workspace`:
    as query_triangle)."""
    a = _float_array(start, "start", (3, 3))
    b = _float_array(end, "end", (3, 3))
    return _run_query("query_triangle_linear", sdf, (a.ctypes.data, b.ctypes.data), t0, t1,
                      _params_arg(params, method), max_contacts, sdf_motion, workspace)


def _mesh_arg(m, name="mesh"):
    if not isinstance(m, Mesh):
        raise TypeError(f"{name}: expected an sdfccd.Mesh, got {type(m).__name__}")
    return m._handle()


def query_mesh(sdf, mesh, motion=None, t0=0.0, t1=1.0 / 60.0, params=None, method="fwgss", sdf_motion=None,
               max_contacts=64, workspace=None):
    """A rigid mesh: the earliest time of impact over its triangles and the contacts at it (`workspace`: as
    query_triangle)."""
    m = _motion_arg(motion, "motion", False)
    return _run_query("query_mesh", sdf, (_mesh_arg(mesh), C.byref(m)), t0, t1, _params_arg(params, method),
                      max_contacts, sdf_motion, workspace)


def query_mesh_linear(sdf, mesh, start, end, t0=0.0, t1=1.0 / 60.0, params=None, method="fwgss", sdf_motion=None,
                      max_contacts=64, workspace=None):
    """A deforming mesh: its world vertices (V, 3) move linearly from `start` at t0 to `end` at t1 (`workspace`:
    as query_triangle)."""
    h = _mesh_arg(mesh)
    nv = mesh.info()["vertex_count"]
    a = _float_array(start, "start", (nv, 3))
    b = _float_array(end, "end", (nv, 3))
    return _run_query("query_mesh_linear", sdf, (h, a.ctypes.data, b.ctypes.data), t0, t1,
                      _params_arg(params, method), max_contacts, sdf_motion, workspace)


_BATCH_DTYPE = np.dtype(_lib.BatchQuery)


def query_batch(sdf, triangles=None, motions=None, t0=0.0, t1=1.0 / 60.0, params=None, method="fwgss", threads=1,
                max_contacts=8, triangles_end=None, meshes=None, sdf_motion=None):
    """Many independent queries in one sdfccd_query_batch call on `threads` native threads (the GIL
    is released meanwhile; results are bitwise those of the single queries, whatever the thread count).

    Rigid triangles: ``triangles`` (N, 3, 3) local vertices with ``motions`` (N,) MOTION_DTYPE (see
    :func:`motions`) or one Motion for all. Linear triangles: ``triangles`` (N, 3, 3) world start and
    ``triangles_end`` (N, 3, 3). Rigid meshes: ``meshes`` (a list of N Mesh) with ``motions``.
    Returns (results (N,) RESULT_DTYPE, contacts (N, max_contacts) CONTACT_DTYPE): result i's
    ``contact_count`` first contacts of row i are valid. A failing query raises Error (the first)."""
    sid = _sdf_arg(sdf, "sdf")
    p = _params_arg(params, method)
    cap = _capacity(max_contacts)
    nthreads = _int(threads, "threads")
    if not 1 <= nthreads <= 256:
        raise ValueError("threads: in [1, 256]")
    t0 = _scalar(t0, "t0")
    t1 = _scalar(t1, "t1")
    keep = []
    if meshes is not None:
        if triangles is not None or triangles_end is not None:
            raise ValueError("meshes: not together with triangles")
        meshes = list(meshes)
        n = len(meshes)
        kind = 2
    else:
        if triangles is None:
            raise ValueError("query_batch: triangles or meshes needed")
        tri = _float_array(triangles, "triangles", (-1, 3, 3))
        keep.append(tri)
        n = tri.shape[0]
        kind = 0
        if triangles_end is not None:
            if motions is not None:
                raise ValueError("triangles_end: linear queries take no motions")
            end = _float_array(triangles_end, "triangles_end", (n, 3, 3))
            keep.append(end)
            kind = 1
    if n > 2**31 - 1:
        raise ValueError("query_batch: too many queries")
    q = np.zeros(n, dtype=_BATCH_DTYPE)
    q["kind"] = kind
    q["sdf"]["index1"] = sid.index1
    q["sdf"]["generation"] = sid.generation
    idx = np.arange(n, dtype=np.uint64)
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    if sm is not None:
        q["sdf_motion"] = C.addressof(sm)
    if kind != 1:
        if isinstance(motions, Motion) or motions is None:
            one = _motion_arg(motions, "motions", False)
            keep.append(one)
            q["motion"] = C.addressof(one)
        else:
            if not isinstance(motions, np.ndarray) or motions.dtype != MOTION_DTYPE:
                raise TypeError("motions: expected a MOTION_DTYPE array (sdfccd.motions(n)) or an sdfccd.Motion")
            if motions.shape != (n,):
                raise ValueError(f"motions: expected shape ({n},), got {motions.shape}")
            mo = np.ascontiguousarray(motions)
            for f in ("position", "orientation", "local_center", "linear_velocity", "angular_velocity"):
                if not np.isfinite(mo[f]).all():
                    raise ValueError(f"motions: non-finite {f}")
            keep.append(mo)
            q["motion"] = mo.ctypes.data + idx * MOTION_DTYPE.itemsize
    if kind == 2:
        for i, m in enumerate(meshes):
            h = _mesh_arg(m, f"meshes[{i}]")
            q["mesh"][i] = (h.index1, h.generation)
    else:
        q["triangle"] = keep[0].ctypes.data + idx * 72
        if kind == 1:
            q["triangle_end"] = keep[1].ctypes.data + idx * 72
    q["t0"] = t0
    q["t1"] = t1
    q["params"] = C.addressof(p)
    contacts = np.zeros((n, cap), dtype=CONTACT_DTYPE)
    results = np.zeros(n, dtype=RESULT_DTYPE)
    if cap:
        q["out_contacts"] = contacts.ctypes.data + idx * (cap * CONTACT_DTYPE.itemsize)
    q["capacity"] = cap
    q["out_result"] = results.ctypes.data + idx * RESULT_DTYPE.itemsize
    if n == 0:
        return results, contacts
    st = _L.sdfccd_query_batch(q.ctypes.data, n, nthreads)
    _raise_callback_errors(sdf)
    _check(st)
    return results, contacts


def extract_isosurface(sdf, lo, hi, resolution=64):
    """The surface phi = 0 of `sdf` inside the box [lo, hi] (marching tetrahedra on resolution^3 cells)
    -> (vertices (V, 3) float64, indices (T, 3) uint32)."""
    box = _lib.Aabb()
    box.lo[:] = _float_array(lo, "lo", (3,))
    box.hi[:] = _float_array(hi, "hi", (3,))
    mid = _lib.MeshId()
    st = _L.sdfccd_extract_isosurface(_sdf_arg(sdf, "sdf"), box, _int(resolution, "resolution"), C.byref(mid))
    _raise_callback_errors(sdf)
    _check(st)
    with Mesh._wrap(mid) as m:
        return m.arrays()


# ---------------------------------------------------------------------------------------------
# contacts and the no-tunnelling guard (contact.h)

#: sdfccd_ContactPoint: point, surface_point, normal, gap, toi, barycentric, triangle, feature_kind,
#: feature, id.
CONTACT_POINT_DTYPE = np.dtype(_lib.ContactPoint)
GUARD_STATES = ("clear", "rolled_back", "inside_at_start")


#: True when the loaded libsdfccd has contact.h's functions (otherwise those raise Error SDFCCD_UNSUPPORTED).
HAVE_CONTACTS = _lib.HAVE_CONTACTS


class Workspace:
    """Reusable scratch storage of the guard and contact calls (sdfccd_Workspace): after a first call
    of a given size they allocate nothing. One thread at a time; freed by close(), ``with`` or GC."""

    def __init__(self):
        _need_contacts()
        ptr = C.c_void_p()
        _check(_L.sdfccd_create_workspace(C.byref(ptr)))
        self._ptr = ptr
        self._lock = threading.Lock()

    def _handle(self):
        if self._ptr is None:
            raise Error("SDFCCD_INVALID_HANDLE", "Workspace is closed")
        return self._ptr

    def close(self):
        with self._lock:
            ptr, self._ptr = self._ptr, None
        if ptr is not None:
            _L.sdfccd_destroy_workspace(ptr)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_ptr", None) is not None:
            try:
                self.close()
            except Exception:
                pass


def _need_contacts():
    if not _lib.HAVE_CONTACTS:
        raise Error("SDFCCD_UNSUPPORTED", f"{_lib.library_path} has no contact functions (contact.h, issue 19)")


def _with_workspace(workspace, fn):
    if workspace is None:
        with Workspace() as ws:
            return fn(ws._handle())
    if not isinstance(workspace, Workspace):
        raise TypeError(f"workspace: expected an sdfccd.Workspace, got {type(workspace).__name__}")
    with workspace._lock:
        return fn(workspace._handle())


def motion_from_poses(start_position, start_orientation, end_position, end_orientation, t0, t1,
                      center=(0.0, 0.0, 0.0)):
    """The rigid Motion that moves `center` (local frame) linearly and turns by the shortest arc from the
    start pose to the end pose over [t0, t1] (sdfccd_rigid_motion_from_poses)."""
    _need_contacts()
    a, b = _lib.Pose(), _lib.Pose()
    a.position[:] = _float_array(start_position, "start_position", (3,))
    a.orientation[:] = _float_array(start_orientation, "start_orientation", (4,))
    b.position[:] = _float_array(end_position, "end_position", (3,))
    b.orientation[:] = _float_array(end_orientation, "end_orientation", (4,))
    m = Motion()
    _check(_L.sdfccd_rigid_motion_from_poses(C.byref(a), C.byref(b), _vec3(center, "center"), _scalar(t0, "t0"),
                                             _scalar(t1, "t1"), C.byref(m._c)))
    return m


class GuardResult:
    """What the guard found: ``state`` ("clear", "rolled_back", "inside_at_start"), ``toi``, ``fraction``,
    ``safe_position`` / ``safe_orientation`` (rigid), ``point``, ``normal``, ``triangle`` (rolled back),
    ``min_gap_start``, ``deep_triangles``, ``query_state``, ``queries``, ``sdf_evaluations``; for the
    linear guard ``positions`` (the vertices at ``toi``)."""

    def __init__(self, g, positions=None):
        self.state = GUARD_STATES[g.state] if 0 <= g.state < len(GUARD_STATES) else g.state
        self.toi = g.toi
        self.fraction = g.fraction
        self.safe_position = np.array(g.safe_pose.position)
        self.safe_orientation = np.array(g.safe_pose.orientation)
        self.point = np.array(g.point)
        self.normal = np.array(g.normal)
        self.min_gap_start = g.min_gap_start
        self.triangle = g.triangle
        self.deep_triangles = g.deep_triangles
        self.query_state = STATES[g.query_state] if 0 <= g.query_state < len(STATES) else g.query_state
        self.queries = g.queries
        self.sdf_evaluations = g.sdf_evaluations
        self.positions = positions

    def __repr__(self):
        return f"GuardResult(state={self.state!r}, toi={self.toi!r}, sdf_evaluations={self.sdf_evaluations})"


def _guard_params(tolerance, params, method):
    g = _L.sdfccd_default_guard_params()
    if tolerance is not None:
        g.tolerance = _scalar(tolerance, "tolerance")
    if params is not None or method != "fwgss":
        g.query = _params_arg(params, method)
    return g


def guard_rigid(sdf, mesh, executed, t0=0.0, t1=1.0 / 60.0, tolerance=None, params=None, method="fwgss",
                sdf_motion=None, workspace=None):
    """The no-tunnelling guarantee (sdfccd_guard_rigid): checks the motion a rigid mesh executed over
    [t0, t1] and, when a point went deeper than `tolerance` (default 5e-4 m), returns the safe pose at
    the time of impact ("rolled_back")."""
    _need_contacts()
    h_sdf, h_mesh = _sdf_arg(sdf, "sdf"), _mesh_arg(mesh)
    m = _motion_arg(executed, "executed", False)
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    g = _guard_params(tolerance, params, method)
    out = _lib.GuardResult()
    a, b = _scalar(t0, "t0"), _scalar(t1, "t1")
    st = _with_workspace(workspace, lambda ws: _L.sdfccd_guard_rigid(
        ws, h_sdf, C.byref(sm) if sm is not None else None, h_mesh, C.byref(m), a, b, C.byref(g), C.byref(out)))
    _raise_callback_errors(sdf)
    _check(st)
    return GuardResult(out)


def guard_linear(sdf, mesh, start, end, t0=0.0, t1=1.0 / 60.0, tolerance=None, params=None, method="fwgss",
                 sdf_motion=None, workspace=None):
    """The guarantee for a deforming mesh (sdfccd_guard_linear): world vertices (V, 3) moving linearly
    from `start` to `end`; the result's ``positions`` are the safe vertex positions at its ``toi``."""
    _need_contacts()
    h_sdf, h_mesh = _sdf_arg(sdf, "sdf"), _mesh_arg(mesh)
    nv = mesh.info()["vertex_count"]
    a_pos = _float_array(start, "start", (nv, 3))
    b_pos = _float_array(end, "end", (nv, 3))
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    g = _guard_params(tolerance, params, method)
    out = _lib.GuardResult()
    positions = np.empty((nv, 3))
    a, b = _scalar(t0, "t0"), _scalar(t1, "t1")
    st = _with_workspace(workspace, lambda ws: _L.sdfccd_guard_linear(
        ws, h_sdf, C.byref(sm) if sm is not None else None, h_mesh, a_pos.ctypes.data, b_pos.ctypes.data, a, b,
        C.byref(g), C.byref(out), positions.ctypes.data))
    _raise_callback_errors(sdf)
    _check(st)
    return GuardResult(out, positions)


def _pair_arg(p, name, struct, fields, sizes):
    """A pair of arrays (e.g. (position, orientation w x y z)) as `struct`'s two `fields` of `sizes`."""
    if not isinstance(p, (tuple, list)) or len(p) != 2:
        raise TypeError(f"{name}: expected ({fields[0]}, {fields[1]})")
    out = struct()
    for f, v, n in zip(fields, p, sizes):
        getattr(out, f)[:] = _float_array(v, f"{name} {f}", (n,))
    return out


def _pose_arg(p, name):
    return _pair_arg(p, name, _lib.Pose, ("position", "orientation"), (3, 4))


def _box_arg(b, name):
    return _pair_arg(b, name, _lib.Aabb, ("lo", "hi"), (3, 3))


def _state_arg(d, name):
    """A body state dict (center, linear_velocity, angular_velocity, inverse_mass, inverse_inertia 3x3)."""
    out = _lib.BodyState()
    out.center[:] = _float_array(d["center"], f"{name} center", (3,))
    out.linear_velocity[:] = _float_array(d.get("linear_velocity", (0.0, 0.0, 0.0)), f"{name} linear_velocity", (3,))
    out.angular_velocity[:] = _float_array(d.get("angular_velocity", (0.0, 0.0, 0.0)), f"{name} angular_velocity", (3,))
    out.inverse_mass = _scalar(d.get("inverse_mass", 0.0), f"{name} inverse_mass")
    out.inverse_inertia[:] = _float_array(d.get("inverse_inertia", np.zeros((3, 3))), f"{name} inverse_inertia", (3, 3)).ravel()
    return out


def _moving_arg(out, d, name):
    """The poses, boxes and reach that an SDF and a body of guard_world share ("end" defaults to "start")."""
    out.start = _pose_arg(d["start"], f"{name} start")
    out.end = _pose_arg(d.get("end", d["start"]), f"{name} end")
    out.start_box = _box_arg(d["start_box"], f"{name} start_box")
    out.end_box = _box_arg(d.get("end_box", d["start_box"]), f"{name} end_box")
    out.reach = _scalar(d.get("reach", 0.0), f"{name} reach")
    out.friction = _scalar(d.get("friction", 0.0), f"{name} friction")


def guard_world(sdfs, bodies, t0=0.0, t1=1.0 / 60.0, tolerance=None, params=None, method="fwgss", workspace=None):
    """The guarantee for a world after an engine's step (sdfccd_guard_world), from plain data.

    `sdfs`: dicts with "sdf" (an Sdf), "start" and "end" poses ((position, orientation w x y z); "end"
    defaults to "start": static), "start_box" and "end_box" ((lo, hi)), "reach" (its points' largest
    distance from its origin), and optionally "friction", "body" (the index in `bodies` of the body
    that carries it), "state" (a state dict: its kinematic or static rigid body), "shape_key".
    `bodies`: dicts with the same poses, boxes, reach and friction, "parts" (a list of (Mesh, offset
    pose), or of (Mesh, offset pose, shape_key)) and "state" (dict: center, linear_velocity,
    angular_velocity, inverse_mass, inverse_inertia 3x3, at the end pose).
    Returns one dict per body: rolled_back, sdf, part (indices, -1), position and orientation (where the
    body is to be), center, linear_velocity, angular_velocity, guard (a GuardResult), queries, failures,
    sdf_evaluations."""
    _need_contacts()
    cs = (_lib.GuardSdf * max(1, len(sdfs)))()
    for i, d in enumerate(sdfs):
        cs[i].sdf = _sdf_arg(d["sdf"], f"sdfs[{i}] sdf")
        _moving_arg(cs[i], d, f"sdfs[{i}]")
        cs[i].shape_key = int(d.get("shape_key", 0))
        cs[i].body = int(d.get("body", -1))
        if d.get("state") is not None:
            cs[i].has_state = 1
            cs[i].state = _state_arg(d["state"], f"sdfs[{i}] state")
    cb = (_lib.GuardRigidBody * max(1, len(bodies)))()
    keep = []
    for i, d in enumerate(bodies):
        _moving_arg(cb[i], d, f"bodies[{i}]")
        cb[i].state = _state_arg(d["state"], f"bodies[{i}] state")
        parts = d.get("parts", ())
        cp = (_lib.GuardPart * max(1, len(parts)))()
        for k, part in enumerate(parts):
            cp[k].mesh = _mesh_arg(part[0], f"bodies[{i}] parts[{k}]")
            cp[k].offset = _pose_arg(part[1], f"bodies[{i}] parts[{k}] offset")
            cp[k].shape_key = int(part[2]) if len(part) > 2 else 0
        keep.append(cp)
        cb[i].parts = cp
        cb[i].part_count = len(parts)
    g = _guard_params(tolerance, params, method)
    out = (_lib.GuardWorldResult * max(1, len(bodies)))()
    a, b = _scalar(t0, "t0"), _scalar(t1, "t1")
    st = _with_workspace(workspace, lambda ws: _L.sdfccd_guard_world(ws, cs, len(sdfs), cb, len(bodies), a, b, C.byref(g),
                                                                     None, None, out))
    _raise_callback_errors(*[d["sdf"] for d in sdfs])
    _check(st)
    results = []
    for i in range(len(bodies)):
        r = out[i]
        results.append({
            "rolled_back": bool(r.rolled_back), "sdf": r.sdf, "part": r.part,
            "position": np.array(r.pose.position), "orientation": np.array(r.pose.orientation),
            "center": np.array(r.state.center), "linear_velocity": np.array(r.state.linear_velocity),
            "angular_velocity": np.array(r.state.angular_velocity), "guard": GuardResult(r.guard),
            "queries": r.queries, "failures": r.failures, "sdf_evaluations": r.sdf_evaluations,
        })
    return results


def _contact_params(params, method, vertex_distance, same_place_distance):
    c = _L.sdfccd_default_contact_params()
    if params is not None or method != "fwgss":
        c.query = _params_arg(params, method)
    if vertex_distance is not None:
        c.vertex_distance = _scalar(vertex_distance, "vertex_distance")
    if same_place_distance is not None:
        c.same_place_distance = _scalar(same_place_distance, "same_place_distance")
    return c


def _contact_set(cs):
    return {"count": cs.count, "candidates": cs.candidates, "started_in_contact": bool(cs.started_in_contact),
            "ccd_ran": bool(cs.ccd_ran), "ccd_state": STATES[cs.ccd_state] if 0 <= cs.ccd_state < len(STATES)
            else cs.ccd_state, "toi": cs.toi, "sdf_evaluations": cs.sdf_evaluations}


def _generate(fn_call, sdf, capacity):
    cap = _capacity(capacity)
    pts = np.zeros(cap, dtype=CONTACT_POINT_DTYPE)
    cs = _lib.ContactSet()
    st = fn_call(pts.ctypes.data if cap else None, cap, C.byref(cs))
    _raise_callback_errors(sdf)
    _check(st)
    return pts[: cs.count], _contact_set(cs)


def generate_contacts(sdf, mesh, motion=None, t0=0.0, t1=1.0 / 60.0, capacity=4, params=None, method="fwgss",
                      vertex_distance=None, same_place_distance=None, sdf_motion=None, workspace=None):
    """The contact set of a rigid mesh against an SDF over a step (sdfccd_generate_contacts), reduced to
    `capacity` points -> (CONTACT_POINT_DTYPE array, summary dict). ``params`` are the CCD's (its
    margin is the contact distance)."""
    _need_contacts()
    h_sdf, h_mesh = _sdf_arg(sdf, "sdf"), _mesh_arg(mesh)
    m = _motion_arg(motion, "motion", False)
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    c = _contact_params(params, method, vertex_distance, same_place_distance)
    a, b = _scalar(t0, "t0"), _scalar(t1, "t1")
    return _generate(lambda out, cap, cs: _with_workspace(workspace, lambda ws: _L.sdfccd_generate_contacts(
        ws, h_sdf, C.byref(sm) if sm is not None else None, h_mesh, C.byref(m), a, b, C.byref(c), out, cap, cs)),
        sdf, capacity)


def generate_contacts_linear(sdf, mesh, start, end, t0=0.0, t1=1.0 / 60.0, capacity=4, params=None, method="fwgss",
                             vertex_distance=None, same_place_distance=None, sdf_motion=None, workspace=None):
    """generate_contacts for a deforming mesh: world vertices (V, 3) moving linearly from `start` to `end`."""
    _need_contacts()
    h_sdf, h_mesh = _sdf_arg(sdf, "sdf"), _mesh_arg(mesh)
    nv = mesh.info()["vertex_count"]
    a_pos = _float_array(start, "start", (nv, 3))
    b_pos = _float_array(end, "end", (nv, 3))
    sm = _motion_arg(sdf_motion, "sdf_motion", True)
    c = _contact_params(params, method, vertex_distance, same_place_distance)
    a, b = _scalar(t0, "t0"), _scalar(t1, "t1")
    return _generate(lambda out, cap, cs: _with_workspace(workspace, lambda ws: _L.sdfccd_generate_contacts_linear(
        ws, h_sdf, C.byref(sm) if sm is not None else None, h_mesh, a_pos.ctypes.data, b_pos.ctypes.data, a, b,
        C.byref(c), out, cap, cs)), sdf, capacity)


def reduce_contacts(points, capacity, same_place_distance=1e-4):
    """Indices (int32) of at most `capacity` points of a CONTACT_POINT_DTYPE array that the library's
    reduction keeps (deepest, then the most contact area, never two at one place)."""
    _need_contacts()
    if not isinstance(points, np.ndarray) or points.dtype != CONTACT_POINT_DTYPE or points.ndim != 1:
        raise TypeError("points: expected a 1-D CONTACT_POINT_DTYPE array")
    pts = np.ascontiguousarray(points)
    cap = _capacity(capacity)
    idx = np.zeros(max(cap, 1), dtype=np.int32)
    n = C.c_int32()
    _check(_L.sdfccd_reduce_contacts(pts.ctypes.data if len(pts) else None, len(pts),
                                     _scalar(same_place_distance, "same_place_distance"), idx.ctypes.data, cap,
                                     C.byref(n)))
    return idx[: n.value].copy()


# ---------------------------------------------------------------------------------------------
# case files

#: The columns of `sdfccd_cases`' CSV, in order.
CASES_COLUMNS = ("id", "hit", "state", "toi", "x", "y", "z", "nx", "ny", "nz", "triangles_tested", "sdf_evals", "micros")


def _cases_dtype(id_len):
    return np.dtype([("id", f"U{max(id_len, 1)}"), ("hit", np.int32), ("state", "U13"), ("toi", np.float64),
                     ("x", np.float64), ("y", np.float64), ("z", np.float64), ("nx", np.float64), ("ny", np.float64),
                     ("nz", np.float64), ("triangles_tested", np.int64), ("sdf_evals", np.int64),
                     ("micros", np.float64)])


CASES_DTYPE = _cases_dtype(64)


def run_cases(path, method="fwgss", subdivision=True, margin=0.0, params=None):
    """Runs a case file exactly as ``sdfccd_cases [--method M] [--no-subdivision] [--margin M] FILE``
    (the same library code) and returns a structured array with its CSV's columns (CASES_COLUMNS):
    equal values bit for bit, NaN where the CSV field is empty (no hit). ``micros`` is the query's
    wall time, never reproducible (the CSV rounds it to 0.001 µs). A malformed file raises Error with
    the message sdfccd_cases prints after "sdfccd_cases: ". ``params`` (a dict of fields or
    :func:`params`) sets the queries' parameters in full; then subdivision and margin are not applied."""
    d = _L.sdfccd_default_case_run_def()
    p = _params_arg(params, method)
    if params is None:
        p.subdivision = 1 if subdivision else 0
        p.margin = _scalar(margin, "margin")
    d.params = p
    run = C.c_void_p()
    _check(_L.sdfccd_run_case_file(_path(path), C.byref(d), C.byref(run)))
    try:
        n = _L.sdfccd_case_run_row_count(run)
        rows = _L.sdfccd_case_run_rows(run)
        ids = [C.string_at(rows[i].id).decode("utf-8", "surrogateescape") for i in range(n)]
        out = np.zeros(n, dtype=_cases_dtype(max((len(s) for s in ids), default=1)))
        if n:
            block = (_lib.CaseRow * n).from_address(C.addressof(rows.contents))
            raw = np.frombuffer(block, dtype=np.dtype(_lib.CaseRow))
            out["id"] = ids
            out["hit"] = raw["hit"]
            out["state"] = [_L.sdfccd_case_state_string(int(s)).decode() for s in raw["state"]]
            out["toi"] = raw["toi"]
            out["x"], out["y"], out["z"] = raw["point"][:, 0], raw["point"][:, 1], raw["point"][:, 2]
            out["nx"], out["ny"], out["nz"] = raw["normal"][:, 0], raw["normal"][:, 1], raw["normal"][:, 2]
            out["triangles_tested"] = raw["triangles_tested"]
            out["sdf_evals"] = raw["sdf_evaluations"]
            out["micros"] = raw["micros"]
    finally:
        _L.sdfccd_destroy_case_run(run)
    return out
