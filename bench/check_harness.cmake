# The benchmarks' harness (bench/harness.hpp), checked on the built benchmarks: every one answers
# --help with its options (exit 0, --json among them) and refuses an unknown option with one line
# naming itself (exit 2); a small bench_delaunay run with --json writes its configuration and
# its table (columns and a row) as JSON. Called by ctest with -DBENCH_DIR=<dir> -DBENCHES=a;b;...
foreach(bench IN LISTS BENCHES)
  execute_process(COMMAND ${BENCH_DIR}/${bench} --help RESULT_VARIABLE rc OUTPUT_VARIABLE help
                  ERROR_VARIABLE help_err)
  if(NOT rc EQUAL 0 OR NOT help MATCHES "--json" OR NOT help MATCHES "Usage: ${bench}")
    message(FATAL_ERROR "${bench} --help: exit ${rc}, output:\n${help}${help_err}")
  endif()
  set(required)  # the positional arguments a program requires
  if(bench STREQUAL "profile_sort")
    set(required linear robust)
  endif()
  execute_process(COMMAND ${BENCH_DIR}/${bench} ${required} --no-such-option RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "^${bench}: .*--no-such-option")
    message(FATAL_ERROR "${bench} --no-such-option: exit ${rc}, standard error:\n${err}")
  endif()
endforeach()

set(json ${WORK_DIR}/bench_delaunay.json)
file(REMOVE ${json})
execute_process(COMMAND ${BENCH_DIR}/bench_delaunay --sizes=100 --budget=0.5 --queries=1
                        --schedulers=robust --json ${json}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${json})
  message(FATAL_ERROR "bench_delaunay --json: exit ${rc}\n${out}${err}")
endif()
file(READ ${json} text)
string(JSON program GET "${text}" program)
string(JSON sizes GET "${text}" options sizes)
string(JSON tables LENGTH "${text}" tables)
string(JSON first_column GET "${text}" tables 0 columns 0)
string(JSON rows LENGTH "${text}" tables 0 rows)
string(JSON n GET "${text}" tables 0 rows 0 1)
if(NOT program STREQUAL "bench_delaunay" OR NOT sizes STREQUAL "100" OR tables LESS 1
   OR NOT first_column STREQUAL "scheduler" OR NOT rows EQUAL 1 OR NOT n EQUAL 100)
  message(FATAL_ERROR "bench_delaunay --json: unexpected document\n${text}")
endif()
if(NOT out MATCHES "# options: --sizes=100 ")
  message(FATAL_ERROR "bench_delaunay: no configuration line\n${out}")
endif()
