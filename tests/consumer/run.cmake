# ctest -P script: install the build tree into a scratch prefix, then configure, build and run
# tests/consumer against it with find_package(vitri): a predicate check (main.cpp) and the Mesher example
# of docs/guide.md (its first ```cpp block, cut as in tests/docs), run from the source root.
set(prefix ${BINARY_DIR}/consumer-prefix)
set(build ${BINARY_DIR}/consumer-build)
file(REMOVE_RECURSE ${prefix} ${build})
file(READ ${SOURCE_DIR}/docs/guide.md text)
string(FIND "${text}" "\n```cpp\n" start)
if(start EQUAL -1)
  message(FATAL_ERROR "docs/guide.md has no ```cpp block")
endif()
math(EXPR start "${start} + 8")
string(SUBSTRING "${text}" ${start} -1 text)
string(FIND "${text}" "\n```" stop)
string(SUBSTRING "${text}" 0 ${stop} code)
file(WRITE ${build}-guide.cpp "${code}\n")
foreach(step
    "${CMAKE_COMMAND};--install;${BINARY_DIR};--prefix;${prefix}"
    "${CMAKE_COMMAND};-S;${SOURCE_DIR}/tests/consumer;-B;${build};-DCMAKE_PREFIX_PATH=${prefix};-DCMAKE_BUILD_TYPE=Release;-DGUIDE_SOURCE=${build}-guide.cpp"
    "${CMAKE_COMMAND};--build;${build}"
    "${build}/consumer"
    "${build}/guide_example")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  WORKING_DIRECTORY ${SOURCE_DIR})
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${step}\n${out}\n${err}")
  endif()
endforeach()
message(STATUS "installed vitri found and used by a consumer project (predicates and the Mesher)")
