# SPDX-License-Identifier: MIT
# Replays the committed fuzz corpora (seeds and issue 11's regression inputs) with any compiler:
# each fuzz target linked with replay_main.c instead of libFuzzer, one ctest test per target.
set(_fuzz_dir ${PROJECT_SOURCE_DIR}/tests/fuzz)
foreach(_t fuzz_query fuzz_cdf fuzz_cases fuzz_mesh)
  add_executable(${_t}_replay ${_fuzz_dir}/${_t}.c ${_fuzz_dir}/replay_main.c)
  target_link_libraries(${_t}_replay PRIVATE sdfccd m)
  target_compile_definitions(${_t}_replay PRIVATE _POSIX_C_SOURCE=200809L)
  sdfccd_target_defaults(${_t}_replay)
  add_test(NAME ${_t}_replay COMMAND ${_t}_replay ${_fuzz_dir}/corpus/${_t})
endforeach()
# assimp's own leaks on malformed STL files (a corpus input) are not sdfccd's: suppressed under LSan.
set_tests_properties(fuzz_mesh_replay PROPERTIES ENVIRONMENT "LSAN_OPTIONS=suppressions=${_fuzz_dir}/lsan.supp")
