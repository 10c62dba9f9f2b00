# Runs one libFuzzer harness for a short while on a private copy of its seeds.
# libFuzzer adds new inputs to its first corpus folder, so the seeds (the
# checked-in corpus and the shared assets, which must never change) are copied
# into WORK first. Called by the fuzz.<name>.short tests:
#   cmake -DFUZZER=<exe> -DWORK=<dir> -DSEEDS=<dir;file;...> -DSECONDS=20 -DTIMEOUT=2 -P run_fuzz.cmake
# A seed that is a file (a finding) goes into the folder findings/.
if(NOT FUZZER OR NOT WORK)
  message(FATAL_ERROR "run_fuzz.cmake needs FUZZER and WORK")
endif()
if(NOT SECONDS)
  set(SECONDS 20)
endif()
if(NOT TIMEOUT)
  set(TIMEOUT 2)
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/corpus" "${WORK}/artifacts")
set(i 0)
foreach(seed IN LISTS SEEDS)
  if(IS_DIRECTORY "${seed}")
    # One subfolder per seed folder: file names may repeat between folders.
    file(COPY "${seed}/" DESTINATION "${WORK}/corpus/seed${i}")
    math(EXPR i "${i} + 1")
  elseif(EXISTS "${seed}")
    file(COPY "${seed}" DESTINATION "${WORK}/corpus/findings")
  endif()
endforeach()
execute_process(
  COMMAND "${FUZZER}" -max_total_time=${SECONDS} -timeout=${TIMEOUT} -rss_limit_mb=2048
          -max_len=1048576 -print_final_stats=1 -artifact_prefix=${WORK}/artifacts/
          "${WORK}/corpus"
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  # libFuzzer's timeout is wall-clock: on a loaded machine a fast input can
  # exceed it. A timeout alone is re-run and counts only when its CPU time is
  # at least half the timeout (docs/fuzzing.md).
  file(GLOB artifacts "${WORK}/artifacts/*")
  file(GLOB timeouts "${WORK}/artifacts/timeout-*")
  list(LENGTH artifacts n_artifacts)
  list(LENGTH timeouts n_timeouts)
  if(n_timeouts EQUAL 1 AND n_artifacts EQUAL 1 AND EXISTS /usr/bin/time)
    execute_process(COMMAND /usr/bin/time -f "cpu %U" -o "${WORK}/rerun-cpu" "${FUZZER}" ${timeouts}
                    OUTPUT_QUIET ERROR_QUIET RESULT_VARIABLE rerun)
    file(READ "${WORK}/rerun-cpu" out)
    string(REGEX MATCH "cpu ([0-9]+)\\.([0-9]+)" m "${out}")
    math(EXPR limit_cs "${TIMEOUT} * 50")  # half the timeout, in centiseconds
    if(m AND rerun EQUAL 0)
      math(EXPR cpu_cs "${CMAKE_MATCH_1} * 100 + ${CMAKE_MATCH_2}")
      if(cpu_cs LESS limit_cs)
        file(RENAME ${timeouts} "${WORK}/slow-under-load-input")
        message(WARNING "${FUZZER}: wall-clock timeout, but the input takes ${CMAKE_MATCH_1}.${CMAKE_MATCH_2} s CPU "
                        "(machine loaded?); kept as ${WORK}/slow-under-load-input, not a failure")
        return()
      endif()
    endif()
  endif()
  message(FATAL_ERROR "${FUZZER} failed (${rc}); reproducer in ${WORK}/artifacts/")
endif()
