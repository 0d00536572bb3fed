/* SPDX-License-Identifier: MIT */
/** @file base.h
 * Version, status codes, error messages, allocator hooks and configuration queries.
 *
 * Error policy: every sdfccd function that can fail returns an ::sdfccd_Status. On failure
 * it writes nothing to its out-parameters unless stated, leaves no partial object behind,
 * and records a human-readable message retrievable with sdfccd_last_error() in the calling
 * thread. The library never prints and never aborts on bad input.
 *
 * Threads: queries and evaluations may run concurrently from any number of threads, also on the
 * same SDF and mesh handles. Creating and destroying handles is thread-safe too, but a handle
 * must not be destroyed while another thread is still using it in a call. sdfccd_set_allocator()
 * must not race with any other call.
 */
#ifndef SDFCCD_BASE_H
#define SDFCCD_BASE_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32) && defined(SDFCCD_SHARED)
#  if defined(SDFCCD_BUILDING)
#    define SDFCCD_API __declspec(dllexport)
#  else
#    define SDFCCD_API __declspec(dllimport)
#  endif
#elif defined(SDFCCD_SHARED) && defined(SDFCCD_BUILDING)
#  define SDFCCD_API __attribute__((visibility("default")))
#else
#  define SDFCCD_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define SDFCCD_VERSION_MAJOR 0
#define SDFCCD_VERSION_MINOR 1
#define SDFCCD_VERSION_PATCH 0
/** Encoded as major * 10000 + minor * 100 + patch. */
#define SDFCCD_VERSION_ID (SDFCCD_VERSION_MAJOR * 10000 + SDFCCD_VERSION_MINOR * 100 + SDFCCD_VERSION_PATCH)

/** Status of a call. 0 is success; every other value comes with a message (sdfccd_last_error). */
typedef enum sdfccd_Status {
    SDFCCD_OK = 0,
    SDFCCD_INVALID_ARGUMENT,   /**< NULL pointer, NaN/Inf value, t1 < t0, bad parameter. */
    SDFCCD_INVALID_HANDLE,     /**< Unknown, destroyed or wrong-kind handle. */
    SDFCCD_DEGENERATE,         /**< Zero-area triangle, empty mesh, or other unusable geometry. */
    SDFCCD_OUT_OF_MEMORY,      /**< The allocator returned NULL. */
    SDFCCD_IO_ERROR,           /**< A file could not be opened, read or written. */
    SDFCCD_FORMAT_ERROR,       /**< A file was read but its content is invalid or truncated. */
    SDFCCD_UNSUPPORTED,        /**< A valid request this build or object cannot serve. */
    SDFCCD_BAD_STATE,          /**< The call is not allowed now (e.g. changing the allocator while memory is live). */
    SDFCCD_STATUS_COUNT
} sdfccd_Status;

/** Short constant name of a status, e.g. "SDFCCD_INVALID_ARGUMENT". Never NULL. */
SDFCCD_API const char* sdfccd_status_string(sdfccd_Status status);

/** Message of the most recent failing call in this thread ("" if none). The string stays
 * valid until the next failing call in this thread. */
SDFCCD_API const char* sdfccd_last_error(void);

/** Allocation hook: returns memory aligned for any scalar type, or NULL. */
typedef void* sdfccd_AllocFcn(size_t size, void* user);
/** Free hook: `size` is the size passed to the matching alloc. */
typedef void sdfccd_FreeFcn(void* mem, size_t size, void* user);

/** Routes every allocation of the library through `alloc`/`free` (both NULL restores malloc/free).
 * Only allowed while no library memory is live (sdfccd_byte_count() == 0); otherwise
 * ::SDFCCD_BAD_STATE. */
SDFCCD_API sdfccd_Status sdfccd_set_allocator(sdfccd_AllocFcn* alloc, sdfccd_FreeFcn* free_fcn, void* user);

/** Bytes currently allocated by the library (handles, meshes, grids). 0 once everything is destroyed. */
SDFCCD_API int64_t sdfccd_byte_count(void);

/** Version of the library binary, as SDFCCD_VERSION_ID. Compare with the header's macro to
 * detect a header/library mismatch. */
SDFCCD_API int32_t sdfccd_version(void);
/** "0.1.0". */
SDFCCD_API const char* sdfccd_version_string(void);
/** One line describing the build: scalar type, optional components (assimp), compiler. */
SDFCCD_API const char* sdfccd_configuration_string(void);
/** 1: all scalars in the ABI are `double` (always true in this version). */
SDFCCD_API int sdfccd_is_double_precision(void);

#ifdef __cplusplus
}
#endif
#endif
