# Distributed SILC (included from tests/CMakeLists.txt; docs/distributed.md):
# the SPMD checks of test_mpi.c under mpirun at np = 1, 2, 3; the same
# checks as a client of `mpirun -np P silcd --mpi` at np = 1, 2, 3; the
# language, API, truth and CLI suites, the Python client and the examples
# against `mpirun -np 2 silcd --mpi`; and a rank killed under a live session
# (test_mpi_faults.sh).  np <= 3 on this 2-core machine: np = 3 runs
# oversubscribed, which the environment allows.  Every test has a timeout,
# so a hang fails instead of blocking CI.
if(NOT TARGET silc_mpi OR NOT TARGET silcd OR NOT TARGET silc_diffusion OR NOT MPIEXEC_EXECUTABLE)
  message(STATUS "SILC: MPI tests skipped (MPI, libsilc_mpi or silcd --mpi not built)")
  return()
endif()
set(SILC_MPI_ENV "${SILC_TEST_ENV};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")

foreach(mode spmd client)
  add_executable(test_mpi_${mode} ${CMAKE_CURRENT_LIST_DIR}/test_mpi.c)
  target_include_directories(test_mpi_${mode} PRIVATE ${CMAKE_CURRENT_LIST_DIR} ${PROJECT_SOURCE_DIR}/examples)
  target_compile_definitions(test_mpi_${mode} PRIVATE SILC_SHARED_MATRICES="${SILC_SHARED_MATRICES}")
  target_link_libraries(test_mpi_${mode} PRIVATE silc silc_diffusion ${MATH_LIB})
endforeach()
target_compile_definitions(test_mpi_spmd PRIVATE SILC_TEST_SPMD=1)
target_link_libraries(test_mpi_spmd PRIVATE silc_mpi)

foreach(np 1 2 3)
  add_test(NAME test_mpi_spmd_np${np}
           COMMAND ${MPIEXEC_EXECUTABLE} -np ${np} $<TARGET_FILE:test_mpi_spmd> spmd)
  add_test(NAME test_mpi_server_np${np}
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_mpi_server.sh ${MPIEXEC_EXECUTABLE} ${np}
                   $<TARGET_FILE:silcd> $<TARGET_FILE:test_mpi_client>
                   ${CMAKE_CURRENT_BINARY_DIR}/mpi-server-np${np})
  set_tests_properties(test_mpi_spmd_np${np} test_mpi_server_np${np} PROPERTIES
                       ENVIRONMENT "${SILC_MPI_ENV}" TIMEOUT 300 RUN_SERIAL TRUE)
endforeach()

# The suites of tests/remote.cmake against `mpirun -np 2 silcd --mpi`, where
# small values stay whole (the default --dist-min-rows 1000) and larger
# ones are split: the same results and messages as any server.
string(MD5 _mpi_hash "${CMAKE_BINARY_DIR}/mpi")
string(SUBSTRING "${_mpi_hash}" 0 12 _mpi_hash)
set(SILC_MPI_SOCKET "/tmp/silcd-mpi-${_mpi_hash}.sock")
set(_mpi_state ${CMAKE_CURRENT_BINARY_DIR}/silcd-mpi-fixture)
add_test(NAME silcd_mpi_start COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/remote_server.sh start
         $<TARGET_FILE:silcd> ${SILC_MPI_SOCKET} ${_mpi_state} --mpi)
add_test(NAME silcd_mpi_stop COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/remote_server.sh stop
         $<TARGET_FILE:silcd> ${SILC_MPI_SOCKET} ${_mpi_state})
set_tests_properties(silcd_mpi_start PROPERTIES FIXTURES_SETUP silcd_mpi
                     ENVIRONMENT "${SILC_MPI_ENV};SILC_LAUNCH=${MPIEXEC_EXECUTABLE} -np 2;SILC_WISDOM=${_mpi_state}/wisdom")
set_tests_properties(silcd_mpi_stop PROPERTIES FIXTURES_CLEANUP silcd_mpi)
set(_mpi_remote_env "${SILC_TEST_ENV};SILC_SERVER=unix:${SILC_MPI_SOCKET}")
foreach(t test_api test_lang test_truth test_examples test_interrupt)
  if(TARGET ${t})
    add_test(NAME ${t}_mpi_server COMMAND ${t})
    set_tests_properties(${t}_mpi_server PROPERTIES ENVIRONMENT "${_mpi_remote_env}" TIMEOUT 600
                         FIXTURES_REQUIRED silcd_mpi RESOURCE_LOCK silcd_mpi)
  endif()
endforeach()
add_test(NAME test_cli_mpi_server COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_cli.sh $<TARGET_FILE:silc_cli>)
add_test(NAME example_diffusion2d_mpi_server
         COMMAND diffusion2d -n 40 -s 5 -o ${CMAKE_CURRENT_BINARY_DIR}/diffusion2d_mpi_server.pgm)
set_tests_properties(test_cli_mpi_server example_diffusion2d_mpi_server PROPERTIES
  ENVIRONMENT "${_mpi_remote_env}" TIMEOUT 600 FIXTURES_REQUIRED silcd_mpi RESOURCE_LOCK silcd_mpi)
if(SILC_SYSTEM_PYTHON)
  add_test(NAME test_python_mpi_server COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/test_python.py
           ${PROJECT_SOURCE_DIR}/bindings/python)
  set_tests_properties(test_python_mpi_server PROPERTIES ENVIRONMENT "${_mpi_remote_env}" TIMEOUT 120
                       FIXTURES_REQUIRED silcd_mpi RESOURCE_LOCK silcd_mpi)
endif()

# The SPMD example, against the embedded example's numbers.
if(TARGET diffusion2d_mpi)
  add_test(NAME example_diffusion2d_spmd
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_mpi_example.sh ${MPIEXEC_EXECUTABLE}
                   $<TARGET_FILE:diffusion2d> $<TARGET_FILE:diffusion2d_mpi> ${CMAKE_CURRENT_BINARY_DIR})
  set_tests_properties(example_diffusion2d_spmd PROPERTIES ENVIRONMENT "${SILC_MPI_ENV}" TIMEOUT 300
                       RUN_SERIAL TRUE)
endif()

# A rank that dies under a live session: the client gets an error, not a hang.
add_test(NAME test_mpi_faults
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_mpi_faults.sh ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:silcd>
                 $<TARGET_FILE:silc_cli> ${CMAKE_CURRENT_BINARY_DIR}/mpi-faults)
set_tests_properties(test_mpi_faults PROPERTIES ENVIRONMENT "${SILC_MPI_ENV}" TIMEOUT 180 RUN_SERIAL TRUE)

# Two simulated hosts (network namespaces and a veth pair, MPI over TCP
# only): the SPMD example and silcd --mpi across them.  Skipped (77), with
# the reason, where namespaces cannot be created (not root).
if(TARGET diffusion2d_mpi)
  add_test(NAME test_mpi_hosts
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_mpi_hosts.sh ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:silcd>
                   $<TARGET_FILE:silc_cli> $<TARGET_FILE:diffusion2d> $<TARGET_FILE:diffusion2d_mpi>
                   ${CMAKE_CURRENT_BINARY_DIR}/mpi-hosts)
  set_tests_properties(test_mpi_hosts PROPERTIES ENVIRONMENT "${SILC_MPI_ENV}" TIMEOUT 300 RUN_SERIAL TRUE
                       SKIP_RETURN_CODE 77)
endif()
