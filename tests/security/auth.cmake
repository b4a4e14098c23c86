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
