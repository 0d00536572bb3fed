# SPDX-License-Identifier: MIT
# Per-target defaults shared by every sdfccd target (no global flags).
function(sdfccd_target_defaults target)
  get_target_property(_type ${target} TYPE)
  if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE
      $<$<COMPILE_LANGUAGE:C>:-Wall -Wextra -Wshadow -Wno-unused-parameter>
      $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wno-unused-parameter>)
  endif()
  if(SDFCCD_FUZZ)
    # libFuzzer build: coverage instrumentation plus ASan and UBSan in every library target.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    if(_type STREQUAL "STATIC_LIBRARY")
      target_link_options(${target} INTERFACE -fsanitize=address,undefined)
    endif()
  endif()
  if(SDFCCD_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    if(_type STREQUAL "STATIC_LIBRARY")
      # Whoever links an instrumented archive needs the sanitizer runtimes too.
      target_link_options(${target} INTERFACE -fsanitize=address,undefined)
    elseif(_type STREQUAL "SHARED_LIBRARY")
      # An instrumented shared library needs ASan's runtime first in the executable's library list
      # ("ASan runtime does not come first"), so whoever links it is linked with the flags too
      # (also through the installed package: sdfccd::sdfccd_shared, and sdfccd.pc's Libs).
      target_link_options(${target} PUBLIC -fsanitize=address,undefined)
    elseif(NOT _type STREQUAL "OBJECT_LIBRARY")
      target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    endif()
  endif()
endfunction()
