# SPDX-License-Identifier: MIT
"""ctypes declarations of libsdfccd's C ABI (capi/include/sdfccd/*.h) and the loading of the library.

Structs embed vectors as ``c_double * 3`` (the same layout as sdfccd_Vec3) so that numpy dtypes made
from them (``numpy.dtype(Struct)``) have ``(3,)`` sub-arrays. tests/test_layout.py checks every size
and offset against the C compiler's (python/layout_probe.c).
"""
import ctypes as C
import os

c_double3 = C.c_double * 3
c_double4 = C.c_double * 4


class Vec3(C.Structure):
    _fields_ = [("x", C.c_double), ("y", C.c_double), ("z", C.c_double)]


class Aabb(C.Structure):
    _fields_ = [("lo", c_double3), ("hi", c_double3)]


class Pose(C.Structure):
    _fields_ = [("position", c_double3), ("orientation", c_double4)]  # orientation: w, x, y, z


class SdfId(C.Structure):
    _fields_ = [("index1", C.c_uint32), ("generation", C.c_uint32)]


class MeshId(C.Structure):
    _fields_ = [("index1", C.c_uint32), ("generation", C.c_uint32)]


class QueryParams(C.Structure):
    _fields_ = [
        ("method", C.c_int32),
        ("margin", C.c_double),
        ("time_tolerance", C.c_double),
        ("distance_tolerance", C.c_double),
        ("max_iterations", C.c_int32),
        ("max_line_search_iterations", C.c_int32),
        ("fwgss_restarts", C.c_int32),
        ("fwgss_vertex_trace", C.c_int32),
        ("subdivision", C.c_int32),
        ("subdivision_min_area", C.c_double),
        ("subdivision_max_depth", C.c_int32),
        ("contact_slop", C.c_double),
        ("toi_window", C.c_double),
        ("max_rotation_per_segment", C.c_double),
        ("certified_time_tolerance", C.c_double),
        ("certified_max_regions", C.c_int32),
        ("broad_phase", C.c_int32),
        ("internal_value", C.c_int32),
        ("max_sdf_evaluations", C.c_int64),
        ("fwgss_secant_entry", C.c_int32),
        ("fwgss_speed_tolerance", C.c_int32),
        ("fwgss_clear_proof", C.c_int32),
        ("fwgss_brent_spatial", C.c_int32),
        ("fwgss_gap_tolerance", C.c_double),
        ("certified_max_bytes", C.c_int64),
        ("fwgss_derivative_spatial", C.c_int32),
        ("fwgss_restart_at_witness", C.c_int32),
        ("fwgss_kink_guard", C.c_int32),
    ]


class RigidMotion(C.Structure):
    _fields_ = [
        ("position", c_double3),
        ("orientation", c_double4),
        ("local_center", c_double3),
        ("linear_velocity", c_double3),
        ("angular_velocity", c_double3),
    ]


class Contact(C.Structure):
    _fields_ = [
        ("point", c_double3),
        ("normal", c_double3),
        ("distance", C.c_double),
        ("gap_t0", C.c_double),
        ("toi", C.c_double),
        ("barycentric", c_double3),
        ("triangle", C.c_uint32),
        ("kind", C.c_int32),
    ]


class QueryResult(C.Structure):
    _fields_ = [
        ("state", C.c_int32),
        ("hit", C.c_int32),
        ("toi", C.c_double),
        ("fraction", C.c_double),
        ("toi_lower", C.c_double),
        ("contact_count", C.c_int32),
        ("contacts_found", C.c_int32),
        ("iterations", C.c_int64),
        ("sdf_evaluations", C.c_int64),
        ("triangles_tested", C.c_int64),
    ]


class BatchQuery(C.Structure):
    _fields_ = [
        ("kind", C.c_int32),
        ("sdf", SdfId),
        ("sdf_motion", C.c_void_p),
        ("mesh", MeshId),
        ("triangle", C.c_void_p),
        ("triangle_end", C.c_void_p),
        ("start", C.c_void_p),
        ("end", C.c_void_p),
        ("motion", C.c_void_p),
        ("t0", C.c_double),
        ("t1", C.c_double),
        ("params", C.c_void_p),
        ("out_contacts", C.c_void_p),
        ("capacity", C.c_int32),
        ("out_result", C.c_void_p),
        ("status", C.c_int32),
    ]


EvalFcn = C.CFUNCTYPE(C.c_double, Vec3, C.POINTER(Vec3), C.c_void_p)
EvalXyzFcn = C.CFUNCTYPE(C.c_double, C.c_double, C.c_double, C.c_double, C.POINTER(Vec3), C.c_void_p)
ProgressFcn = C.CFUNCTYPE(C.c_int32, C.c_double, C.c_void_p)


class CallbackSdfDef(C.Structure):
    _fields_ = [
        ("eval", EvalFcn),
        ("user", C.c_void_p),
        ("lipschitz", C.c_double),
        ("bounds", Aabb),
        ("smooth", C.c_int32),
        ("eval_xyz", EvalXyzFcn),
        ("internal_value", C.c_int32),
    ]


class SpikeGridDef(C.Structure):
    _fields_ = [
        ("spacing", C.c_double),
        ("base_radius", C.c_double),
        ("height", C.c_double),
        ("count_x", C.c_int32),
        ("count_y", C.c_int32),
        ("internal_value", C.c_int32),
    ]


class SdfInfo(C.Structure):
    _fields_ = [
        ("kind", C.c_int32),
        ("domain", Aabb),
        ("bounds", Aabb),
        ("lipschitz", C.c_double),
        ("memory_bytes", C.c_int64),
    ]


class MeshDef(C.Structure):
    _fields_ = [
        ("vertices", C.c_void_p),
        ("vertex_count", C.c_uint32),
        ("indices", C.c_void_p),
        ("triangle_count", C.c_uint32),
        ("drop_degenerate", C.c_int32),
        ("internal_value", C.c_int32),
    ]


class MeshInfo(C.Structure):
    _fields_ = [
        ("vertex_count", C.c_uint32),
        ("triangle_count", C.c_uint32),
        ("dropped_triangles", C.c_uint32),
        ("bounds", Aabb),
        ("memory_bytes", C.c_int64),
    ]


class MeshLoadDef(C.Structure):
    _fields_ = [
        ("scale", C.c_double),
        ("merge_vertices", C.c_int32),
        ("drop_degenerate", C.c_int32),
        ("internal_value", C.c_int32),
        ("max_file_bytes", C.c_int64),
        ("formats", C.c_char_p),
    ]


class GridDef(C.Structure):
    _fields_ = [
        ("resolution", C.c_int32 * 3),
        ("fit_domain", C.c_int32),
        ("domain", Aabb),
        ("padding", C.c_double),
        ("band", C.c_double),
        ("threads", C.c_int32),
        ("invert", C.c_int32),
        ("allow_open_mesh", C.c_int32),
        ("progress", ProgressFcn),
        ("progress_user", C.c_void_p),
        ("internal_value", C.c_int32),
        ("max_bytes", C.c_int64),
    ]


class GridInfo(C.Structure):
    _fields_ = [
        ("resolution", C.c_int32 * 3),
        ("domain", Aabb),
        ("cell_size", c_double3),
        ("field_count", C.c_int32),
        ("cell_count", C.c_int64),
        ("stored_cells", C.c_int64),
        ("valued_cells", C.c_int64),
        ("node_count", C.c_int64),
        ("memory_bytes", C.c_int64),
        ("file_bytes", C.c_int64),
        ("max_lipschitz", C.c_double),
        ("band", C.c_double),
    ]


class CaseRow(C.Structure):
    _fields_ = [
        ("id", C.c_void_p),  # const char* (C.string_at); c_void_p keeps numpy.dtype(CaseRow) possible
        ("line", C.c_int32),
        ("hit", C.c_int32),
        ("state", C.c_int32),
        ("toi", C.c_double),
        ("point", c_double3),
        ("normal", c_double3),
        ("triangles_tested", C.c_int64),
        ("sdf_evaluations", C.c_int64),
        ("micros", C.c_double),
    ]


CaseRowFcn = C.CFUNCTYPE(None, C.POINTER(CaseRow), C.c_void_p)


class CaseRunDef(C.Structure):
    _fields_ = [
        ("params", QueryParams),
        ("on_row", CaseRowFcn),
        ("user", C.c_void_p),
        ("name", C.c_char_p),
        ("base_dir", C.c_char_p),
        ("internal_value", C.c_int32),
    ]


# contact.h (issue 19): the guard, contact generation and reduction.
class GuardParams(C.Structure):
    _fields_ = [("tolerance", C.c_double), ("query", QueryParams), ("internal_value", C.c_int32)]


class GuardResult(C.Structure):
    _fields_ = [
        ("state", C.c_int32),
        ("toi", C.c_double),
        ("fraction", C.c_double),
        ("safe_pose", Pose),
        ("point", c_double3),
        ("normal", c_double3),
        ("min_gap_start", C.c_double),
        ("triangle", C.c_uint32),
        ("deep_triangles", C.c_int32),
        ("query_state", C.c_int32),
        ("queries", C.c_int32),
        ("sdf_evaluations", C.c_int64),
        ("pinned", C.c_int32),
        ("certified", C.c_int32),
    ]


class BodyState(C.Structure):
    _fields_ = [
        ("center", c_double3),
        ("linear_velocity", c_double3),
        ("angular_velocity", c_double3),
        ("inverse_mass", C.c_double),
        ("inverse_inertia", C.c_double * 9),
    ]


class GuardSdf(C.Structure):
    _fields_ = [
        ("sdf", SdfId),
        ("start", Pose),
        ("end", Pose),
        ("start_box", Aabb),
        ("end_box", Aabb),
        ("reach", C.c_double),
        ("friction", C.c_double),
        ("shape_key", C.c_uint64),
        ("body", C.c_int32),
        ("has_state", C.c_int32),
        ("state", BodyState),
    ]


class GuardPart(C.Structure):
    _fields_ = [("mesh", MeshId), ("offset", Pose), ("shape_key", C.c_uint64)]


class GuardRigidBody(C.Structure):
    _fields_ = [
        ("start", Pose),
        ("end", Pose),
        ("start_box", Aabb),
        ("end_box", Aabb),
        ("reach", C.c_double),
        ("parts", C.POINTER(GuardPart)),
        ("part_count", C.c_int32),
        ("friction", C.c_double),
        ("state", BodyState),
    ]


class GuardWorldResult(C.Structure):
    _fields_ = [
        ("rolled_back", C.c_int32),
        ("sdf", C.c_int32),
        ("part", C.c_int32),
        ("pose", Pose),
        ("state", BodyState),
        ("guard", GuardResult),
        ("queries", C.c_int32),
        ("failures", C.c_int32),
        ("sdf_evaluations", C.c_int64),
    ]


class ContactPoint(C.Structure):
    _fields_ = [
        ("point", c_double3),
        ("surface_point", c_double3),
        ("normal", c_double3),
        ("gap", C.c_double),
        ("toi", C.c_double),
        ("barycentric", c_double3),
        ("triangle", C.c_uint32),
        ("feature_kind", C.c_int32),
        ("feature", C.c_uint32),
        ("id", C.c_uint64),
    ]


class KeepPrevious(C.Structure):
    _fields_ = [
        ("ids", C.POINTER(C.c_uint64)),
        ("count", C.c_int32),
        ("depth", C.c_double),
        ("share", C.c_double),
    ]


class ContactParams(C.Structure):
    _fields_ = [
        ("query", QueryParams),
        ("vertex_distance", C.c_double),
        ("same_place_distance", C.c_double),
        ("feature_size", C.c_double),
        ("reduced_count", C.c_int32),
        ("cover_depth", C.c_double),
        ("end_skip_travel", C.c_double),
        ("previous", KeepPrevious),
        ("internal_value", C.c_int32),
    ]


class ContactSet(C.Structure):
    _fields_ = [
        ("count", C.c_int32),
        ("candidates", C.c_int32),
        ("started_in_contact", C.c_int32),
        ("ccd_ran", C.c_int32),
        ("ccd_state", C.c_int32),
        ("toi", C.c_double),
        ("sdf_evaluations", C.c_int64),
        ("reduced", C.c_int32),
        ("discrete_queries", C.c_int32),
        ("own_evaluations", C.c_int64),
        ("face_regions", C.c_int64),
    ]


# Every struct the layout test compares with the C compiler's sizeof / offsetof.
STRUCTS = {
    "sdfccd_Vec3": Vec3, "sdfccd_Aabb": Aabb, "sdfccd_Pose": Pose, "sdfccd_SdfId": SdfId,
    "sdfccd_MeshId": MeshId, "sdfccd_QueryParams": QueryParams, "sdfccd_RigidMotion": RigidMotion,
    "sdfccd_Contact": Contact, "sdfccd_QueryResult": QueryResult, "sdfccd_BatchQuery": BatchQuery,
    "sdfccd_CallbackSdfDef": CallbackSdfDef, "sdfccd_SpikeGridDef": SpikeGridDef, "sdfccd_SdfInfo": SdfInfo,
    "sdfccd_MeshDef": MeshDef, "sdfccd_MeshInfo": MeshInfo, "sdfccd_MeshLoadDef": MeshLoadDef,
    "sdfccd_GridDef": GridDef, "sdfccd_GridInfo": GridInfo, "sdfccd_CaseRow": CaseRow,
    "sdfccd_CaseRunDef": CaseRunDef,
}
# contact.h's structs (compared only when the C headers have contact.h).
CONTACT_STRUCTS = {
    "sdfccd_GuardParams": GuardParams, "sdfccd_GuardResult": GuardResult, "sdfccd_ContactPoint": ContactPoint,
    "sdfccd_ContactParams": ContactParams, "sdfccd_ContactSet": ContactSet, "sdfccd_KeepPrevious": KeepPrevious,
    "sdfccd_BodyState": BodyState, "sdfccd_GuardSdf": GuardSdf, "sdfccd_GuardPart": GuardPart,
    "sdfccd_GuardRigidBody": GuardRigidBody, "sdfccd_GuardWorldResult": GuardWorldResult,
}

_S = C.c_int  # sdfccd_Status
_P = C.POINTER
_PROTOTYPES = {
    "sdfccd_status_string": (C.c_char_p, [C.c_int]),
    "sdfccd_last_error": (C.c_char_p, []),
    "sdfccd_byte_count": (C.c_int64, []),
    "sdfccd_version_string": (C.c_char_p, []),
    "sdfccd_configuration_string": (C.c_char_p, []),
    "sdfccd_default_query_params": (QueryParams, []),
    "sdfccd_default_rigid_motion": (RigidMotion, []),
    "sdfccd_create_sphere": (_S, [C.c_double, _P(SdfId)]),
    "sdfccd_create_box": (_S, [Vec3, _P(SdfId)]),
    "sdfccd_create_rounded_box": (_S, [Vec3, C.c_double, _P(SdfId)]),
    "sdfccd_create_torus": (_S, [C.c_double, C.c_double, _P(SdfId)]),
    "sdfccd_create_capsule": (_S, [C.c_double, C.c_double, _P(SdfId)]),
    "sdfccd_create_cylinder": (_S, [C.c_double, C.c_double, _P(SdfId)]),
    "sdfccd_create_half_space": (_S, [Vec3, C.c_double, _P(SdfId)]),
    "sdfccd_default_spike_grid_def": (SpikeGridDef, []),
    "sdfccd_create_spike_grid": (_S, [_P(SpikeGridDef), _P(SdfId)]),
    "sdfccd_create_csg": (_S, [C.c_int, SdfId, SdfId, _P(SdfId)]),
    "sdfccd_create_transformed": (_S, [SdfId, Pose, C.c_double, _P(SdfId)]),
    "sdfccd_default_callback_sdf_def": (CallbackSdfDef, []),
    "sdfccd_create_callback_sdf": (_S, [_P(CallbackSdfDef), _P(SdfId)]),
    "sdfccd_destroy_sdf": (_S, [SdfId]),
    "sdfccd_sdf_eval_batch": (_S, [SdfId, C.c_void_p, C.c_int32, C.c_void_p, C.c_void_p]),
    "sdfccd_sdf_get_info": (_S, [SdfId, _P(SdfInfo)]),
    "sdfccd_default_mesh_def": (MeshDef, []),
    "sdfccd_create_mesh": (_S, [_P(MeshDef), _P(MeshId)]),
    "sdfccd_destroy_mesh": (_S, [MeshId]),
    "sdfccd_mesh_get_info": (_S, [MeshId, _P(MeshInfo)]),
    "sdfccd_mesh_get_data": (_S, [MeshId, C.c_void_p, C.c_void_p]),
    "sdfccd_default_mesh_load_def": (MeshLoadDef, []),
    "sdfccd_load_mesh": (_S, [C.c_char_p, _P(MeshLoadDef), _P(MeshId)]),
    "sdfccd_query_triangle": (_S, [SdfId, _P(RigidMotion), C.c_void_p, _P(RigidMotion), C.c_double, C.c_double,
                                   _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_triangle_linear": (_S, [SdfId, _P(RigidMotion), C.c_void_p, C.c_void_p, C.c_double, C.c_double,
                                          _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_mesh": (_S, [SdfId, _P(RigidMotion), MeshId, _P(RigidMotion), C.c_double, C.c_double,
                               _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_mesh_linear": (_S, [SdfId, _P(RigidMotion), MeshId, C.c_void_p, C.c_void_p, C.c_double, C.c_double,
                                      _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_batch": (_S, [C.c_void_p, C.c_int32, C.c_int32]),
    "sdfccd_extract_isosurface": (_S, [SdfId, Aabb, C.c_int32, _P(MeshId)]),
    "sdfccd_default_grid_def": (GridDef, []),
    "sdfccd_create_grid_from_mesh": (_S, [MeshId, _P(GridDef), _P(SdfId)]),
    "sdfccd_create_grid_from_sdf": (_S, [SdfId, _P(GridDef), _P(SdfId)]),
    "sdfccd_load_grid": (_S, [C.c_char_p, _P(SdfId)]),
    "sdfccd_save_grid": (_S, [SdfId, C.c_char_p]),
    "sdfccd_grid_get_info": (_S, [SdfId, _P(GridInfo)]),
    "sdfccd_default_case_run_def": (CaseRunDef, []),
    "sdfccd_case_state_string": (C.c_char_p, [C.c_int]),
    "sdfccd_run_case_file": (_S, [C.c_char_p, _P(CaseRunDef), _P(C.c_void_p)]),
    "sdfccd_case_run_row_count": (C.c_int64, [C.c_void_p]),
    "sdfccd_case_run_rows": (_P(CaseRow), [C.c_void_p]),
    "sdfccd_destroy_case_run": (None, [C.c_void_p]),
}


# contact.h (issue 19, branch t19core): bound when the library has it (HAVE_CONTACTS).
_OPTIONAL_PROTOTYPES = {
    "sdfccd_create_workspace": (_S, [_P(C.c_void_p)]),
    "sdfccd_destroy_workspace": (None, [C.c_void_p]),
    "sdfccd_rigid_motion_from_poses": (_S, [_P(Pose), _P(Pose), Vec3, C.c_double, C.c_double, _P(RigidMotion)]),
    "sdfccd_default_guard_params": (GuardParams, []),
    "sdfccd_guard_rigid": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, _P(RigidMotion), C.c_double, C.c_double,
                                _P(GuardParams), _P(GuardResult)]),
    "sdfccd_guard_linear": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, C.c_void_p, C.c_void_p, C.c_double,
                                 C.c_double, _P(GuardParams), _P(GuardResult), C.c_void_p]),
    "sdfccd_guard_world": (_S, [C.c_void_p, _P(GuardSdf), C.c_int32, _P(GuardRigidBody), C.c_int32, C.c_double,
                                C.c_double, _P(GuardParams), C.c_void_p, C.c_void_p, _P(GuardWorldResult)]),
    "sdfccd_reduce_contacts": (_S, [C.c_void_p, C.c_int32, C.c_double, C.c_void_p, C.c_int32, _P(C.c_int32)]),
    "sdfccd_default_contact_params": (ContactParams, []),
    "sdfccd_generate_contacts": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, _P(RigidMotion), C.c_double,
                                      C.c_double, _P(ContactParams), C.c_void_p, C.c_int32, _P(ContactSet)]),
    "sdfccd_generate_contacts_linear": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, C.c_void_p, C.c_void_p,
                                             C.c_double, C.c_double, _P(ContactParams), C.c_void_p, C.c_int32,
                                             _P(ContactSet)]),
    "sdfccd_query_triangle_ws": (_S, [C.c_void_p, SdfId, _P(RigidMotion), C.c_void_p, _P(RigidMotion), C.c_double,
                                      C.c_double, _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_triangle_linear_ws": (_S, [C.c_void_p, SdfId, _P(RigidMotion), C.c_void_p, C.c_void_p, C.c_double,
                                             C.c_double, _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_mesh_ws": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, _P(RigidMotion), C.c_double, C.c_double,
                                  _P(QueryParams), C.c_void_p, C.c_int32, _P(QueryResult)]),
    "sdfccd_query_mesh_linear_ws": (_S, [C.c_void_p, SdfId, _P(RigidMotion), MeshId, C.c_void_p, C.c_void_p,
                                         C.c_double, C.c_double, _P(QueryParams), C.c_void_p, C.c_int32,
                                         _P(QueryResult)]),
}
HAVE_CONTACTS = False


def _library_path():
    """SDFCCD_LIBRARY if set, else the path the build or the install wrote into _libpath.py."""
    env = os.environ.get("SDFCCD_LIBRARY")
    if env:
        return env
    try:
        from . import _libpath
    except ImportError:
        raise ImportError("sdfccd: no _libpath.py next to the package (use the package from the build tree "
                          "(build/python) or from an install, or set SDFCCD_LIBRARY to libsdfccd.so)") from None
    path = _libpath.LIBRARY
    if not os.path.isabs(path):
        path = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(_libpath.__file__)), path))
    return path


def load():
    path = _library_path()
    lib = C.CDLL(path)
    for name, (restype, argtypes) in _PROTOTYPES.items():
        fn = getattr(lib, name)
        fn.restype = restype
        fn.argtypes = argtypes
    global HAVE_CONTACTS
    HAVE_CONTACTS = all(hasattr(lib, name) for name in _OPTIONAL_PROTOTYPES)
    if HAVE_CONTACTS:
        for name, (restype, argtypes) in _OPTIONAL_PROTOTYPES.items():
            fn = getattr(lib, name)
            fn.restype = restype
            fn.argtypes = argtypes
    return lib, path


lib, library_path = load()
