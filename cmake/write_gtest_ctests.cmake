# Included by CTest (from the file CMakeLists.txt writes for each test binary), so that the tests
# are listed from the binary as it is whenever CTest runs: registers its GoogleTests. A test
# matching a pattern of cmake/host_only_tests.cmake is a CTest of its own (`Suite.Test`, no
# label); the other tests of a suite open an OpenCL device and run together in one process, one
# CTest per suite (`Suite.*`, label `device`): a process that opens the device pays for loading
# the driver and for fetching each kernel program from PoCL's cache, which took longer than the
# test itself for most of them. DISABLED_ tests are reports run by hand, never registered.
#
# Variables: BINARY (the test executable), HOST_ONLY (the patterns, ':'-separated, as a gtest
# filter), WORKING_DIR, SUITE_COSTS (optional, "Suite=seconds" ':'-separated: the CTest COST of
# those suites' CTests, so that `ctest -j` starts them early).
foreach(variable BINARY HOST_ONLY WORKING_DIR)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "cmake/write_gtest_ctests.cmake: ${variable} is not set")
  endif()
endforeach()

execute_process(COMMAND "${BINARY}" --gtest_list_tests
                OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE result TIMEOUT 60)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${BINARY} --gtest_list_tests failed (${result}):\n${errors}")
endif()

# gtest filter patterns ('*' any run, '?' one character) as anchored regular expressions.
set(host_only_regexes "")
string(REPLACE ":" ";" host_only_patterns "${HOST_ONLY}")
foreach(pattern IN LISTS host_only_patterns)
  string(REGEX REPLACE "([.+^$()|\\[\\]{}\\\\])" "\\\\\\1" regex "${pattern}")
  string(REPLACE "*" ".*" regex "${regex}")
  string(REPLACE "?" "." regex "${regex}")
  list(APPEND host_only_regexes "^${regex}$")
endforeach()

string(REPLACE "\n" ";" lines "${listing}")
set(suite "")
set(suites "")
foreach(line IN LISTS lines)
  # "Suite." starts a suite, "  Test" is one of its tests; "  # ..." after either is a comment.
  string(REGEX REPLACE "  #.*$" "" line "${line}")
  if(line STREQUAL "" OR line MATCHES "^Running main\\(\\) from ")
    continue()
  elseif(line MATCHES "^([^ ]+)\\.$")
    set(suite "${CMAKE_MATCH_1}")
  elseif(NOT line MATCHES "^  ([^ ]+)$")
    message(FATAL_ERROR "cmake/write_gtest_ctests.cmake: ${BINARY} --gtest_list_tests printed a line that is no suite or test: '${line}'")
  else()
    set(name "${suite}.${CMAKE_MATCH_1}")
    if(name MATCHES "^DISABLED_|\\.DISABLED_")
      continue()
    endif()
    set(host_only FALSE)
    foreach(regex IN LISTS host_only_regexes)
      if(name MATCHES "${regex}")
        set(host_only TRUE)
        break()
      endif()
    endforeach()
    if(host_only)
      add_test("${name}" "${BINARY}" "--gtest_filter=${name}")
      set_tests_properties("${name}" PROPERTIES WORKING_DIRECTORY "${WORKING_DIR}")
    else()
      if(NOT DEFINED device_${suite})
        list(APPEND suites "${suite}")
        set(device_${suite} "")
      endif()
      list(APPEND device_${suite} "${name}")
    endif()
  endif()
endforeach()

string(REPLACE ":" ";" suite_costs "${SUITE_COSTS}")
foreach(suite IN LISTS suites)
  list(JOIN device_${suite} ":" filter)
  add_test("${suite}.*" "${BINARY}" "--gtest_filter=${filter}")
  set_tests_properties("${suite}.*" PROPERTIES WORKING_DIRECTORY "${WORKING_DIR}" LABELS device)
  foreach(entry IN LISTS suite_costs)
    if(entry MATCHES "^${suite}=([0-9]+)$")
      set_tests_properties("${suite}.*" PROPERTIES COST ${CMAKE_MATCH_1})
    endif()
  endforeach()
endforeach()
