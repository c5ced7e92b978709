# Checks the installed package as a user meets it, after moving it:
#
#   cmake -DKINETIC_BUILD_DIR=<build dir of kinetic, already built>
#         -DKINETIC_SOURCE_DIR=<kinetic source dir>
#         [-DKINETIC_SANITIZE=ON|OFF]
#         -P tests/packaging/test_install.cmake
#
# 1. Install the build into a fresh prefix, then move the prefix to another directory.
# 2. No installed CMake or pkg-config file names the first prefix, the build or source tree, or
#    an absolute library path; the targets do not require nlohmann-json.
# 3. CMake: configure examples/ with find_package(kinetic 0.2 COMPONENTS scenario) against the
#    moved prefix, build, and run every example (each checks its answers against brute force);
#    find_package(kinetic 0.1) and (kinetic 0.3) are refused, (kinetic 0.2.0 EXACT) accepted.
# 4. pkg-config: compile an example of each module (kinetic, kinetic-scenario) with the flags of
#    `pkg-config --cflags --libs` against the moved prefix and run it.
# 5. docs/getting-started.md followed as written: its CMake project, its pkg-config build and its
#    task programs built against the prefix (as $HOME/.local), each printing the page's output.
# 6. The installed command-line program runs from the moved prefix.
# Any failing step is a FATAL_ERROR that shows the step's command and output.
cmake_minimum_required(VERSION 3.25)

foreach(var KINETIC_BUILD_DIR KINETIC_SOURCE_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "test_install: -D${var}=... is required")
  endif()
endforeach()
if(NOT DEFINED KINETIC_SANITIZE)
  set(KINETIC_SANITIZE OFF)
endif()
if(NOT EXISTS "${KINETIC_BUILD_DIR}/CMakeCache.txt")
  message(FATAL_ERROR "test_install: ${KINETIC_BUILD_DIR} is not a configured build directory")
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
kinetic_read_cache(CMAKE_INSTALL_LIBDIR libdir)
if(build_type STREQUAL "")
  set(build_type Release)
endif()
if(libdir STREQUAL "")
  set(libdir lib)
endif()
if(cxx_compiler STREQUAL "")
  set(cxx_compiler c++)
endif()

set(work_dir "${KINETIC_BUILD_DIR}/packaging")
set(first_prefix "${work_dir}/first-prefix")
set(prefix "${work_dir}/moved/to/another/place")
file(REMOVE_RECURSE "${work_dir}")
file(MAKE_DIRECTORY "${work_dir}/moved/to/another")

# Runs a command; on failure stops with the step's name, the command and everything it printed.
function(kinetic_step name)
  message(STATUS "test_install: ${name}")
  execute_process(COMMAND ${ARGN}
                  RESULT_VARIABLE result
                  OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(NOT result STREQUAL "0")
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "test_install: step '${name}' failed (${result})\n"
                        "command: ${command}\n"
                        "output:\n${output}")
  endif()
  set(step_output "${output}" PARENT_SCOPE)
endfunction()

# Runs a command that must fail; stops when it succeeds.
function(kinetic_step_fails name)
  message(STATUS "test_install: ${name}")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE output
                  ERROR_VARIABLE output)
  if(result STREQUAL "0")
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "test_install: step '${name}' succeeded but must fail\n"
                        "command: ${command}\noutput:\n${output}")
  endif()
endfunction()

# --- 1. Install, then move the prefix. ----------------------------------------------------------
kinetic_step("install into ${first_prefix}"
  "${CMAKE_COMMAND}" --install "${KINETIC_BUILD_DIR}" --prefix "${first_prefix}"
  --config "${build_type}")
file(RENAME "${first_prefix}" "${prefix}")
message(STATUS "test_install: moved the prefix to ${prefix}")

# --- 2. No absolute path in the package files. -------------------------------------------------
file(GLOB package_files "${prefix}/${libdir}/cmake/kinetic/*.cmake"
                        "${prefix}/${libdir}/pkgconfig/*.pc")
list(LENGTH package_files package_file_count)
if(package_file_count LESS 6)
  message(FATAL_ERROR "test_install: expected the CMake config, version, targets, FindGMP and "
                      "three .pc files; found: ${package_files}")
endif()
foreach(file IN LISTS package_files)
  file(READ "${file}" text)
  foreach(forbidden "${first_prefix}" "${KINETIC_BUILD_DIR}" "${KINETIC_SOURCE_DIR}"
                    "libgmp" "/usr/lib" "nlohmann")
    string(FIND "${text}" "${forbidden}" at)
    if(NOT at EQUAL -1 AND NOT file MATCHES "FindGMP[.]cmake$")
      message(FATAL_ERROR "test_install: ${file} contains '${forbidden}': the installed package "
                          "is not relocatable or forces a dependency on its users")
    endif()
  endforeach()
endforeach()

# --- 3. CMake consumers. --------------------------------------------------------------------------
set(common_args "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_BUILD_TYPE=${build_type}"
                "-DCMAKE_CXX_COMPILER=${cxx_compiler}")
if(NOT generator STREQUAL "")
  list(APPEND common_args -G "${generator}")
endif()
set(sanitize_flags "")
if(KINETIC_SANITIZE)
  # The static libraries were compiled with the sanitizers; the final link needs their runtimes.
  set(sanitize_flags -fsanitize=address,undefined -fno-sanitize-recover=all)
  string(REPLACE ";" " " flags "${sanitize_flags}")
  list(APPEND common_args "-DCMAKE_CXX_FLAGS=${flags} -fno-omit-frame-pointer"
                          "-DCMAKE_EXE_LINKER_FLAGS=${flags}")
endif()

set(examples sort_points kdtree_range tournament_flight_plan segment_tree_stab hull_moving_points
             scenario_run)
set(example_build "${work_dir}/examples-cmake")
kinetic_step("configure examples/ (find_package(kinetic 0.2 COMPONENTS scenario))"
  "${CMAKE_COMMAND}" -S "${KINETIC_SOURCE_DIR}/examples" -B "${example_build}" ${common_args})
kinetic_step("build examples/" "${CMAKE_COMMAND}" --build "${example_build}" --config "${build_type}")
foreach(example IN LISTS examples)
  set(exe "${example_build}/${example}")
  if(NOT EXISTS "${exe}")
    set(exe "${example_build}/${build_type}/${example}")
  endif()
  kinetic_step("run ${example} (CMake build)" "${exe}")
  string(STRIP "${step_output}" step_output)
  message(STATUS "test_install: ${example} says:\n${step_output}")
endforeach()

# The package's version rule: 0.2.x satisfies 0.2 (and 0.2.0 EXACT); 0.1 and 0.3 do not.
function(kinetic_version_project request expect)
  string(MAKE_C_IDENTIFIER "${request}" dir_name)
  set(dir "${work_dir}/version-${dir_name}")
  file(MAKE_DIRECTORY "${dir}")
  file(WRITE "${dir}/CMakeLists.txt"
       "cmake_minimum_required(VERSION 3.25)\nproject(v LANGUAGES CXX)\n"
       "find_package(kinetic ${request} REQUIRED)\n")
  if(expect STREQUAL "found")
    kinetic_step("find_package(kinetic ${request}) is accepted"
      "${CMAKE_COMMAND}" -S "${dir}" -B "${dir}/build" ${common_args})
  else()
    kinetic_step_fails("find_package(kinetic ${request}) is refused"
      "${CMAKE_COMMAND}" -S "${dir}" -B "${dir}/build" ${common_args})
  endif()
endfunction()
kinetic_version_project("0.2.0 EXACT" found)
kinetic_version_project("0.1" refused)
kinetic_version_project("0.3" refused)
kinetic_version_project("1.0" refused)
kinetic_version_project("0.2 COMPONENTS no_such_component" refused)

# --- 4. pkg-config consumers. ---------------------------------------------------------------------
find_program(PKG_CONFIG_EXECUTABLE NAMES pkg-config pkgconf REQUIRED)
set(ENV{PKG_CONFIG_PATH} "${prefix}/${libdir}/pkgconfig")
kinetic_step("pkg-config --modversion kinetic" "${PKG_CONFIG_EXECUTABLE}" --modversion kinetic)
string(STRIP "${step_output}" pc_version)
if(NOT pc_version MATCHES "^0[.]2[.]")
  message(FATAL_ERROR "test_install: pkg-config reports version '${pc_version}', expected 0.2.x")
endif()
# One program per module: the flags are the module's, the same for every program using it (every
# example was built and run through CMake above).
foreach(example IN ITEMS sort_points scenario_run)
  set(module kinetic)
  if(example STREQUAL "scenario_run")
    set(module kinetic-scenario)
  endif()
  kinetic_step("pkg-config --cflags --libs ${module}"
    "${PKG_CONFIG_EXECUTABLE}" --cflags --libs ${module})
  string(STRIP "${step_output}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(exe "${work_dir}/examples-pkg-config/${example}")
  file(MAKE_DIRECTORY "${work_dir}/examples-pkg-config")
  kinetic_step("compile ${example} with pkg-config's flags"
    "${cxx_compiler}" -std=c++20 -O1 ${sanitize_flags}
    "${KINETIC_SOURCE_DIR}/examples/${example}.cpp" -o "${exe}" ${flags})
  kinetic_step("run ${example} (pkg-config build)" "${exe}")
endforeach()

# --- 5. The getting-started page, as a newcomer follows it. ----------------------------------------
# docs/getting-started.md's named blocks (```cpp first.cpp, ```text first.out, ...) are written
# into a directory and run as the page says, with HOME a fresh directory whose .local is the
# installed prefix: its CMake project (CMAKE_PREFIX_PATH), its pkg-config build
# (PKG_CONFIG_PATH), every task program; each output must be the page's.
find_program(KINETIC_PYTHON3 NAMES python3 REQUIRED)
set(page_dir "${work_dir}/getting-started")
kinetic_step("read the getting-started page's blocks"
  "${KINETIC_PYTHON3}" "${KINETIC_SOURCE_DIR}/tests/packaging/page_blocks.py"
  "${KINETIC_SOURCE_DIR}/docs/getting-started.md" "${page_dir}/page")
string(STRIP "${step_output}" page_blocks)
separate_arguments(page_blocks UNIX_COMMAND "${page_blocks}")
file(READ "${page_dir}/page/install.sh" install_text)
string(FIND "${install_text}" "cmake --install build/release --prefix \"$HOME/.local\"" at)
if(at EQUAL -1)
  message(FATAL_ERROR "test_install: the page's install.sh no longer installs into "
                      "\"$HOME/.local\", the prefix the rest of the page and this test use")
endif()
file(MAKE_DIRECTORY "${page_dir}/home" "${page_dir}/bin" "${page_dir}/project")
file(CREATE_LINK "${prefix}" "${page_dir}/home/.local" SYMBOLIC)
# Under the sanitizers the static libraries need their runtimes at the final link: `c++` is
# wrapped to add them (the page's commands stay as they are). The wrapper calls the compiler by
# its full path (never itself), and CXX / CXXFLAGS of the caller's shell are unset so that CMake
# takes `c++` from the PATH as on a newcomer's machine.
set(page_cxx "${cxx_compiler}")
if(NOT IS_ABSOLUTE "${page_cxx}")
  find_program(page_cxx_path NAMES "${page_cxx}" REQUIRED)
  set(page_cxx "${page_cxx_path}")
endif()
string(REPLACE ";" " " wrapper_flags "${sanitize_flags}")
file(WRITE "${page_dir}/bin/c++" "#!/bin/sh\nexec \"${page_cxx}\" ${wrapper_flags} \"$@\"\n")
file(CHMOD "${page_dir}/bin/c++" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
set(page_env HOME=${page_dir}/home "PATH=${page_dir}/bin:$ENV{PATH}" --unset=PKG_CONFIG_PATH
             --unset=CXX --unset=CXXFLAGS --unset=LDFLAGS)
foreach(file IN LISTS page_blocks)
  file(COPY "${page_dir}/page/${file}" DESTINATION "${page_dir}/project")
endforeach()
# The output of a run must end with the page's block `expected`.
function(kinetic_page_output name expected)
  file(READ "${page_dir}/page/${expected}" want)
  string(STRIP "${want}" want)
  string(STRIP "${step_output}" got)
  string(LENGTH "${want}" want_length)
  string(LENGTH "${got}" got_length)
  set(tail "")
  if(got_length GREATER_EQUAL want_length)
    math(EXPR from "${got_length} - ${want_length}")
    string(SUBSTRING "${got}" ${from} -1 tail)
  endif()
  if(NOT tail STREQUAL want)
    message(FATAL_ERROR "test_install: ${name} does not print the page's ${expected}:\n"
                        "page:\n${want}\nprinted:\n${got}")
  endif()
endfunction()
# Every named block is used: install.sh (read above), CMakeLists.txt and the two build scripts
# (the first program), each X.cpp built and run against its X.out, first.py / first-py.out (the
# Python suite's). A block nothing here reads fails the test.
set(page_used install.sh CMakeLists.txt cmake-build.sh pkg-config-build.sh first.cpp first.out
              first.py first-py.out)
set(page_scripts cmake-build.sh)
if(libdir STREQUAL "lib")
  list(APPEND page_scripts pkg-config-build.sh)
else()
  message(STATUS "test_install: the page's pkg-config-build.sh names lib/pkgconfig; this "
                 "install's is ${libdir}/pkgconfig: not run")
endif()
foreach(script IN LISTS page_scripts)
  execute_process(COMMAND "${CMAKE_COMMAND}" -E env ${page_env} sh -e ${script}
                  WORKING_DIRECTORY "${page_dir}/project"
                  RESULT_VARIABLE result OUTPUT_VARIABLE step_output ERROR_VARIABLE step_output)
  if(NOT result STREQUAL "0")
    message(FATAL_ERROR "test_install: the page's ${script} failed (${result}):\n${step_output}")
  endif()
  kinetic_page_output("the page's ${script}" first.out)
  message(STATUS "test_install: the page's ${script} prints first.out")
endforeach()
set(page_tasks "")
foreach(block IN LISTS page_blocks)
  if(block MATCHES "^(.+)[.]cpp$" AND NOT block STREQUAL "first.cpp")
    list(APPEND page_tasks "${CMAKE_MATCH_1}")
    list(APPEND page_used "${block}" "${CMAKE_MATCH_1}.out")
    if(NOT EXISTS "${page_dir}/page/${CMAKE_MATCH_1}.out")
      message(FATAL_ERROR "test_install: the page's ${block} has no ${CMAKE_MATCH_1}.out block")
    endif()
  endif()
endforeach()
foreach(block IN LISTS page_blocks)
  if(NOT block IN_LIST page_used)
    message(FATAL_ERROR "test_install: the page's block ${block} is checked by nothing")
  endif()
endforeach()
list(LENGTH page_tasks task_count)
if(task_count LESS 5)
  message(FATAL_ERROR "test_install: the page has ${task_count} task programs (range, nearest, "
                      "hull, collisions, Delaunay at least): ${page_tasks}")
endif()
foreach(task IN LISTS page_tasks)
  execute_process(
    COMMAND "${CMAKE_COMMAND}" -E env ${page_env}
            "PKG_CONFIG_PATH=${page_dir}/home/.local/${libdir}/pkgconfig" sh -ec
            "c++ -std=c++20 ${task}.cpp $(pkg-config --cflags --libs kinetic) -o ${task} && ./${task}"
    WORKING_DIRECTORY "${page_dir}/project"
    RESULT_VARIABLE result OUTPUT_VARIABLE step_output ERROR_VARIABLE step_output)
  if(NOT result STREQUAL "0")
    message(FATAL_ERROR "test_install: the page's ${task}.cpp failed (${result}):\n${step_output}")
  endif()
  kinetic_page_output("the page's ${task}.cpp" ${task}.out)
  message(STATUS "test_install: the page's ${task}.cpp prints ${task}.out")
endforeach()

# --- 6. The command-line program, when it was built. ----------------------------------------------
if(EXISTS "${prefix}/bin/kinetic")
  kinetic_step("kinetic --version from the moved prefix" "${prefix}/bin/kinetic" --version)
  string(STRIP "${step_output}" cli_version)
  message(STATUS "test_install: ${cli_version}")
endif()
message(STATUS "test_install: passed")
