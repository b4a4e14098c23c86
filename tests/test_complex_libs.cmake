# test_complex_libs: the library plugins' complex solves (issue 31), run by
# a harness with a host of its own (test_complex_libs.c) and checked by
# test_complex_libs.py against NumPy / SciPy.  Registered only when a plugin
# it covers is built and /usr/bin/python3 has SciPy.
if(TARGET silc_plugin_lapack OR TARGET silc_plugin_suitesparse OR TARGET silc_plugin_mumps)
  execute_process(COMMAND /usr/bin/python3 -c "import numpy, scipy.sparse.linalg, scipy.io"
                  RESULT_VARIABLE _cl_scipy OUTPUT_QUIET ERROR_QUIET)
  if(_cl_scipy EQUAL 0)
    add_executable(test_complex_libs test_complex_libs.c)
    target_include_directories(test_complex_libs PRIVATE ${PROJECT_SOURCE_DIR}/plugins)
    target_link_libraries(test_complex_libs PRIVATE ${CMAKE_DL_LIBS} ${MATH_LIB})
    foreach(p lapack suitesparse mumps)
      if(TARGET silc_plugin_${p})
        add_dependencies(test_complex_libs silc_plugin_${p})
      endif()
    endforeach()
    add_test(NAME test_complex_libs
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/test_complex_libs.py
                     $<TARGET_FILE:test_complex_libs> ${PROJECT_BINARY_DIR}/plugins ${SILC_SHARED_MATRICES}
                     ${CMAKE_CURRENT_BINARY_DIR}/complex_libs $<TARGET_FILE:silc_cli>)
    set_tests_properties(test_complex_libs PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 300)
  else()
    message(STATUS "SILC: test_complex_libs skipped: /usr/bin/python3 lacks numpy or scipy")
  endif()
endif()
