# Adding a field to a message is one line in its .lcm file — shown on a scratch copy of lcm_types/ (which
# builds on its own: the .lcm files, lcm-gen, schema_gen.py and the generic code of include/rpem/schema/):
# two lines are added to rpem_estimate_t.lcm, a scalar with a label and a fixed array, and
# add_field_probe.cpp, built against the copy, sets them in the mirror and finds them in the LCM encoding,
# the printed line and the CSV (test test_schema_add_field, tests/schema/CMakeLists.txt).
#
#   cmake -DSOURCE_DIR=REPO -DWORK_DIR=SCRATCH -DGENERATOR=Ninja [-DCXX=c++] [-DLAUNCHER=ccache] -P add_field.cmake
foreach(v SOURCE_DIR WORK_DIR GENERATOR)
  if(NOT ${v})
    message(FATAL_ERROR "add_field.cmake: -D${v}=… is required")
  endif()
endforeach()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
file(COPY ${SOURCE_DIR}/lcm_types DESTINATION ${WORK_DIR})
file(COPY ${SOURCE_DIR}/tests/schema/add_field_probe.cpp DESTINATION ${WORK_DIR})

# The whole change: two lines before the authentication fields, which stay last.
set(lcm ${WORK_DIR}/lcm_types/rpem_estimate_t.lcm)
file(READ ${lcm} text)
set(anchor "\n    // Authentication")
string(FIND "${text}" "${anchor}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "add_field.cmake: no '// Authentication' comment line in ${lcm}")
endif()
string(REPLACE "${anchor}" "
    double  t_probe_C;         // [T_probe] added by tests/schema/add_field.cmake
    int16_t probe_counts[3];
${anchor}" text "${text}")
file(WRITE ${lcm} "${text}")

file(WRITE ${WORK_DIR}/CMakeLists.txt "cmake_minimum_required(VERSION 3.25)
project(add_field LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
add_subdirectory(lcm_types)
add_executable(add_field_probe add_field_probe.cpp)
target_link_libraries(add_field_probe PRIVATE rpem::lcm_types)
")

set(options -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release)
if(CXX)
  list(APPEND options -DCMAKE_CXX_COMPILER=${CXX})
endif()
if(LAUNCHER)
  list(APPEND options -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
string(TIMESTAMP start "%s")
foreach(step configure build run)
  if(step STREQUAL configure)
    set(command ${CMAKE_COMMAND} -S ${WORK_DIR} -B ${WORK_DIR}/build ${options})
  elseif(step STREQUAL build)
    set(command ${CMAKE_COMMAND} --build ${WORK_DIR}/build --target add_field_probe)
  else()
    set(command ${WORK_DIR}/build/add_field_probe)
  endif()
  execute_process(COMMAND ${command} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(step STREQUAL run OR NOT rc EQUAL 0)
    message("${out}")
  endif()
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "add_field.cmake: the scratch tree's ${step} failed (${rc}); it is in ${WORK_DIR}")
  endif()
endforeach()
string(TIMESTAMP end "%s")
math(EXPR seconds "${end} - ${start}")
message("add_field.cmake: a field added to a scratch lcm_types/ reached the encoding, the line and the CSV (${seconds} s)")
