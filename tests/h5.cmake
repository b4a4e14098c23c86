# tests/h5.cmake -- SILC's HDF5 files read and written by h5py and scipy
# (tests/test_h5.py), with Debian's python3 when it has h5py; test_h5 (the
# C side) is in the main list.
if(SILC_SYSTEM_PYTHON AND TARGET silc_cli)
  execute_process(COMMAND ${SILC_SYSTEM_PYTHON} -c "import h5py, scipy" RESULT_VARIABLE _no_h5py
                  OUTPUT_QUIET ERROR_QUIET)
  if(_no_h5py EQUAL 0)
    add_test(NAME test_h5_python COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/test_h5.py
             $<TARGET_FILE:silc_cli>)
    set_tests_properties(test_h5_python PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 300)
  else()
    message(STATUS "SILC: test_h5_python skipped (apt-get install python3-h5py)")
  endif()
endif()
