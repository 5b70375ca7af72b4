# Every test of the build has one of the tiers' labels (tests/CMakeLists.txt): lists the tests that have none.
# cmake -DCTEST=... -DBUILD_DIR=... -P every_test_labelled.cmake
execute_process(COMMAND ${CTEST} --test-dir ${BUILD_DIR} -N -LE "^(unit|integration|threads|experiment|long|sanitize)$"
                OUTPUT_VARIABLE listed RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "ctest -N failed (${status}):\n${listed}")
endif()
string(REGEX MATCH "Total Tests: ([0-9]+)" total "${listed}")
if(NOT total OR NOT CMAKE_MATCH_1 EQUAL 0)
  message(FATAL_ERROR "tests without a label:\n${listed}")
endif()
execute_process(COMMAND ${CTEST} --test-dir ${BUILD_DIR} -N OUTPUT_VARIABLE all)
string(REGEX MATCH "Total Tests: ([0-9]+)" total "${all}")
message(STATUS "all ${CMAKE_MATCH_1} tests have a label")
