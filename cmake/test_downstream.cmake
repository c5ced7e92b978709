# Checks that an installed kinetic can be consumed with find_package(kinetic).
#
#   cmake -DKINETIC_BUILD_DIR=<build dir of kinetic, already built>
#         -DKINETIC_SOURCE_DIR=<kinetic source dir>
#         [-DKINETIC_SANITIZE=ON|OFF]
#         -P cmake/test_downstream.cmake
#
# Steps: install the build into a fresh prefix under <build>/downstream, configure and build
# examples/downstream against it (same compiler, generator and build type as the kinetic build),
# then run the example; any failing step is a FATAL_ERROR that shows the step's output.
cmake_minimum_required(VERSION 3.25)

foreach(var KINETIC_BUILD_DIR KINETIC_SOURCE_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "test_downstream: -D${var}=... is required")
  endif()
endforeach()
if(NOT DEFINED KINETIC_SANITIZE)
  set(KINETIC_SANITIZE OFF)
endif()
if(NOT EXISTS "${KINETIC_BUILD_DIR}/CMakeCache.txt")
  message(FATAL_ERROR "test_downstream: ${KINETIC_BUILD_DIR} is not a configured build directory")
endif()

# Read one entry of the kinetic build's CMakeCache.txt (empty when absent).
function(kinetic_read_cache name out_var)
  file(STRINGS "${KINETIC_BUILD_DIR}/CMakeCache.txt" lines REGEX "^${name}:[A-Z]+=")
  set(value "")
  if(lines)
    list(GET lines 0 line)
    string(REGEX REPLACE "^${name}:[A-Z]+=" "" value "${line}")
  endif()
  set(${out_var} "${value}" PARENT_SCOPE)
endfunction()

kinetic_read_cache(CMAKE_GENERATOR generator)
kinetic_read_cache(CMAKE_CXX_COMPILER cxx_compiler)
kinetic_read_cache(CMAKE_BUILD_TYPE build_type)
if(build_type STREQUAL "")
  set(build_type Release)
endif()

set(work_dir "${KINETIC_BUILD_DIR}/downstream")
set(prefix "${work_dir}/prefix")
set(example_build "${work_dir}/build")
file(REMOVE_RECURSE "${work_dir}")
file(MAKE_DIRECTORY "${work_dir}")

# Runs a command; on failure stops with the step's name, the command and everything it printed.
function(kinetic_step name)
  message(STATUS "test_downstream: ${name}")
  execute_process(COMMAND ${ARGN}
                  RESULT_VARIABLE result
                  OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result STREQUAL "0")
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "test_downstream: step '${name}' failed (${result})\n"
                        "command: ${command}\n"
                        "output:\n${output}")
  endif()
  set(step_output "${output}" PARENT_SCOPE)
endfunction()

# 1. Install the already-built project into a fresh prefix.
kinetic_step("install into ${prefix}"
  "${CMAKE_COMMAND}" --install "${KINETIC_BUILD_DIR}" --prefix "${prefix}" --config "${build_type}")

# 2. Configure and build the downstream example against the installed package.
set(configure_args
  -S "${KINETIC_SOURCE_DIR}/examples/downstream"
  -B "${example_build}"
  "-DCMAKE_PREFIX_PATH=${prefix}"
  "-DCMAKE_BUILD_TYPE=${build_type}")
if(NOT generator STREQUAL "")
  list(APPEND configure_args -G "${generator}")
endif()
if(NOT cxx_compiler STREQUAL "")
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${cxx_compiler}")
endif()
if(KINETIC_SANITIZE)
  # The static library was compiled with the sanitizers; the final link needs their runtimes.
  set(sanitize_flags "-fsanitize=address,undefined -fno-sanitize-recover=all")
  list(APPEND configure_args
    "-DCMAKE_CXX_FLAGS=${sanitize_flags} -fno-omit-frame-pointer"
    "-DCMAKE_EXE_LINKER_FLAGS=${sanitize_flags}")
endif()
kinetic_step("configure examples/downstream" "${CMAKE_COMMAND}" ${configure_args})
kinetic_step("build examples/downstream"
  "${CMAKE_COMMAND}" --build "${example_build}" --config "${build_type}")

# 3. Run the example (single- or multi-configuration generator layout).
set(example "${example_build}/kinetic_downstream")
if(NOT EXISTS "${example}")
  set(example "${example_build}/${build_type}/kinetic_downstream")
endif()
if(NOT EXISTS "${example}")
  message(FATAL_ERROR "test_downstream: built example not found under ${example_build}")
endif()
kinetic_step("run ${example}" "${example}")
string(STRIP "${step_output}" step_output)
message(STATUS "test_downstream: example says: ${step_output}")
message(STATUS "test_downstream: passed")
