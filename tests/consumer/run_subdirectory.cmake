# ctest -P script: configure tests/consumer/subdirectory (a parent project that add_subdirectory()s vitri)
# without a build type, build its consumer program and run it.
set(build ${BINARY_DIR}/subdirectory-consumer-build)
file(REMOVE_RECURSE ${build})
foreach(step
    "${CMAKE_COMMAND};-S;${SOURCE_DIR}/tests/consumer/subdirectory;-B;${build};-DVITRI_SOURCE_DIR=${SOURCE_DIR}"
    "${CMAKE_COMMAND};--build;${build};--target;consumer;--parallel;2"
    "${build}/consumer")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${step}\n${out}\n${err}")
  endif()
endforeach()
message(STATUS "vitri built with add_subdirectory and used by a parent project")
