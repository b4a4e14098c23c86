# Authentication and admission (docs/security.md): who may open a session on
# silcd, how slowly a token can be guessed, silent connections against a real
# client, and silcd's strict options (tests/security/auth.c); the clients of
# every language presenting a token over TCP (auth_clients.sh); and the same
# rules under `mpirun -np 2 silcd --mpi` (auth_mpi.sh).
if(NOT TARGET silcd)
  return()
endif()
silc_add_test(security_auth INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/auth.c)
target_compile_definitions(security_auth PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>")
add_dependencies(security_auth silcd)
set_tests_properties(security_auth PROPERTIES TIMEOUT 180)

if(TARGET silc_cli)
  set(_auth_py none)
  if(SILC_SYSTEM_PYTHON)
    set(_auth_py ${SILC_SYSTEM_PYTHON})
  endif()
  set(_auth_fortran none)
  if(TARGET diffusion1d_fortran)
    set(_auth_fortran $<TARGET_FILE:diffusion1d_fortran>)
  endif()
  add_test(NAME security_auth_clients
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/auth_clients.sh $<TARGET_FILE:silcd>
                   $<TARGET_FILE:silc_cli> ${_auth_py} ${PROJECT_SOURCE_DIR}/bindings/python ${_auth_fortran})
  set_tests_properties(security_auth_clients PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 300)
endif()

if(MPI_C_FOUND AND MPIEXEC_EXECUTABLE AND TARGET silc_cli)
  add_test(NAME security_auth_mpi
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/auth_mpi.sh ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:silcd>
                   $<TARGET_FILE:silc_cli> ${CMAKE_CURRENT_BINARY_DIR}/auth-mpi)
  set_tests_properties(security_auth_mpi PROPERTIES TIMEOUT 300 RUN_SERIAL TRUE ENVIRONMENT
    "${SILC_TEST_ENV};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
endif()
