# The limits a session cannot pass (docs/security.md, "Limits"): memory of
# hostile PUTs, of a statement's temporaries and of the memo, the statement text cap,
# --max-request-seconds (cooperative and forced), --max-cpu, a client gone
# during a runaway, --max-clients against orphaned runaways, SIGTERM and
# SIGKILL of silcd with runaways, factorizations against the session's limit;
# the cases that apply again under
# `mpirun -np 2 silcd --mpi`.  Each case (tests/security/limits.py) starts
# its own server on a Unix socket in the build directory.
if(NOT TARGET silcd OR NOT SILC_SYSTEM_PYTHON)
  message(STATUS "SILC: limit tests skipped (silcd or /usr/bin/python3 missing)")
  return()
endif()
# The misbehaving plugin of the server tests (tests/server/crash_plugin.c,
# built by remote.cmake): alpha 17 never returns, alpha 19 asks
# host->cancelled().
set(_limits_dir ${CMAKE_CURRENT_BINARY_DIR}/security-limits)
set(_limits_env "${SILC_TEST_ENV};STUCK_PLUGIN_DIR=${CMAKE_CURRENT_BINARY_DIR}/crash-plugin")
foreach(case hostile_put request_time peak statement_cap max_cpu disconnect max_clients sigterm
        parent_killed stuck_forced stuck_cooperative stuck_disconnect data_cap)
  add_test(NAME security_limits_${case}
           COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/limits.py
                   ${PROJECT_SOURCE_DIR}/bindings/python ${_limits_dir} ${case} $<TARGET_FILE:silcd>)
  set_tests_properties(security_limits_${case} PROPERTIES ENVIRONMENT "${_limits_env}" TIMEOUT 120)
endforeach()
# The memo's kept results and their UMFPACK factorizations (issue 33); the
# CHOLMOD factorizations of bound values (issue 27); UMFPACK's on huge pages.
if(TARGET silc_plugin_suitesparse)
  foreach(case memo attached attached_huge)
    add_test(NAME security_limits_${case}
             COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/limits.py
                     ${PROJECT_SOURCE_DIR}/bindings/python ${_limits_dir} ${case} $<TARGET_FILE:silcd>)
    set_tests_properties(security_limits_${case} PROPERTIES ENVIRONMENT "${_limits_env}" TIMEOUT 120)
  endforeach()
endif()
# PETSc's printing reaches the client, not silcd's log.
if(TARGET silc_plugin_petsc)
  add_test(NAME security_limits_library_output
           COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/limits.py
                   ${PROJECT_SOURCE_DIR}/bindings/python ${_limits_dir} library_output $<TARGET_FILE:silcd>)
  set_tests_properties(security_limits_library_output PROPERTIES ENVIRONMENT "${_limits_env}" TIMEOUT 120)
endif()
if(TARGET silc_mpi AND MPIEXEC_EXECUTABLE)
  set(_limits_mpi_cases request_time_mpi disconnect_mpi sigterm_mpi idle_cpu_mpi max_cpu_mpi stuck_mpi
                        admission_mpi announce_mpi hostile_put_mpi unread_get_mpi idle_timeout_mpi peer_share_mpi
                        peak_mpi statement_cap_mpi data_cap_mpi)
  if(TARGET silc_plugin_petsc)
    list(APPEND _limits_mpi_cases library_output_mpi)
  endif()
  # MUMPS's factorizations of distributed matrices (issue 27).
  if(TARGET silc_plugin_mumps_mpi)
    list(APPEND _limits_mpi_cases attached_mpi)
  endif()
  foreach(case ${_limits_mpi_cases})
    add_test(NAME security_limits_${case}
             COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/limits.py
                     ${PROJECT_SOURCE_DIR}/bindings/python ${_limits_dir} ${case}
                     $<TARGET_FILE:silcd> ${MPIEXEC_EXECUTABLE})
    set_tests_properties(security_limits_${case} PROPERTIES
      ENVIRONMENT "${_limits_env};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1"
      TIMEOUT 180 RUN_SERIAL TRUE)
  endforeach()
  # Its MUMPS factorizations take seconds each under AddressSanitizer.
  if(TARGET silc_plugin_mumps_mpi)
    set_tests_properties(security_limits_attached_mpi PROPERTIES TIMEOUT 300)
  endif()
endif()
