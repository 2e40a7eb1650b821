# tests/cli_test.cmake — the clvr program end to end (cmake -P): exit codes and one-line errors.
# Inputs: CLVR (the program), SRC (source tree), WORK (scratch folder).
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

function(expect_run expected_rc pattern)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT rc STREQUAL "${expected_rc}")
    message(FATAL_ERROR "${ARGN}\n  exit ${rc}, want ${expected_rc}\n  stdout: ${out}\n  stderr: ${err}")
  endif()
  if(NOT "${out}${err}" MATCHES "${pattern}")
    message(FATAL_ERROR "${ARGN}\n  output does not match '${pattern}'\n  stdout: ${out}\n  stderr: ${err}")
  endif()
endfunction()

expect_run(0 "using device" ${CLVR} info)
expect_run(2 "^clvr: error: " ${CLVR} no-such-command)
expect_run(3 "^clvr: error: .*matches no OpenCL device" ${CLVR} info --device no-such-device-xyz)
