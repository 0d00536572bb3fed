# SPDX-License-Identifier: MIT
# Runs a command and checks both its exit code and its output (WILL_FAIL accepts any failure,
# PASS_REGULAR_EXPRESSION ignores the exit code):
#   cmake -DEXPECT_EXIT=N -DEXPECT_OUTPUT=REGEX [-DREJECT_OUTPUT=REGEX2] -P expect_exit.cmake -- COMMAND ARGS...
# Passes when COMMAND exits with N and its stdout + stderr matches REGEX (and not REGEX2, when
# given) (ARGS without semicolons).
set(_cmd)
set(_after FALSE)
math(EXPR _last "${CMAKE_ARGC} - 1")
foreach(_i RANGE 0 ${_last})
  if(_after)
    list(APPEND _cmd "${CMAKE_ARGV${_i}}")
  elseif(CMAKE_ARGV${_i} STREQUAL "--")
    set(_after TRUE)
  endif()
endforeach()
if(NOT _cmd OR NOT DEFINED EXPECT_EXIT OR NOT DEFINED EXPECT_OUTPUT)
  message(FATAL_ERROR "usage: cmake -DEXPECT_EXIT=N -DEXPECT_OUTPUT=REGEX -P expect_exit.cmake -- COMMAND ARGS...")
endif()
execute_process(COMMAND ${_cmd} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _out)
message("${_out}")
if(NOT _rc STREQUAL "${EXPECT_EXIT}")
  message(FATAL_ERROR "exit code ${_rc}, expected ${EXPECT_EXIT}")
endif()
if(NOT _out MATCHES "${EXPECT_OUTPUT}")
  message(FATAL_ERROR "output does not match '${EXPECT_OUTPUT}'")
endif()
if(DEFINED REJECT_OUTPUT AND _out MATCHES "${REJECT_OUTPUT}")
  message(FATAL_ERROR "output matches '${REJECT_OUTPUT}', which it must not")
endif()
message("exit code ${_rc} and output as expected")
