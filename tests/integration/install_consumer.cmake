# Install the build tree into a scratch prefix, then configure, build and run a tiny consumer project
# that finds it with find_package(PointHaptics).
# cmake -DBUILD_DIR=... -DWORK=... -DSOURCE=... -P install_consumer.cmake
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK}/prefix RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${WORK}/build -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${WORK}/prefix
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer failed: ${out}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/build RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer failed: ${out}")
endif()
execute_process(COMMAND ${WORK}/build/app RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer failed: ${out}")
endif()
message(STATUS "consumer: ${out}")
# the Python package lands where Debian's python3 looks under /usr/local (the default prefix), and imports
# from there
execute_process(COMMAND /usr/bin/python3 -c "import site, sys, sysconfig; v = '%d.%d' % sys.version_info[:2]; \
assert '/usr/local/lib/python' + v + '/dist-packages' in sys.path; print('lib/python' + v + '/dist-packages')"
                RESULT_VARIABLE rc OUTPUT_VARIABLE python_dir ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "python3 does not search /usr/local/lib/python3.X/dist-packages: ${err}")
endif()
if(NOT EXISTS ${WORK}/prefix/${python_dir}/pointhaptics/__init__.py)
  message(FATAL_ERROR "the Python package is not installed in ${python_dir}, where python3 looks under /usr/local")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${WORK}/prefix/${python_dir}
                /usr/bin/python3 -c "import pointhaptics as ph; print('python', ph.__version__, ph.__file__)"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed Python package does not import: ${out}")
endif()
message(STATUS "installed ${out}")
