# tests/install.cmake -- SILC staged with DESTDIR, its prefix moved, and used
# from there: the installed silc and silcd with no environment, an
# out-of-tree project (find_package and pkg-config, C, Fortran, MPI), the
# Python package and the jar (tests/install).  Not in a sanitizer build: an
# uninstrumented program cannot load ASan's libsilc.
if(NOT SILC_SANITIZE)
  set(_install_mpiexec "")
  if(TARGET silc_mpi AND MPIEXEC_EXECUTABLE)
    set(_install_mpiexec ${MPIEXEC_EXECUTABLE})
  endif()
  add_test(NAME test_install COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/install/test_install.sh ${PROJECT_BINARY_DIR}
           ${PROJECT_SOURCE_DIR} ${_install_mpiexec})
  set_tests_properties(test_install PROPERTIES TIMEOUT 300 ENVIRONMENT
    "${SILC_TEST_ENV};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
endif()
