# Files and settings (docs/security.md, "Settings: server and session" and
# "Files"): what a silcd session may not set and which files it may not
# touch, tried against a real silcd on a Unix socket in the build directory,
# on TCP 127.0.0.1 with a token file, and under `mpirun -np 2 silcd --mpi`;
# and the temporary-file race of an embedded program (files_attacks.sh).
if(NOT TARGET silcd OR NOT TARGET silc_cli)
  return()
endif()

# A library named like a plugin whose constructor leaves a marker file.
add_library(silc_security_canary MODULE ${CMAKE_CURRENT_LIST_DIR}/files_canary_plugin.c)
set_target_properties(silc_security_canary PROPERTIES PREFIX "lib" OUTPUT_NAME silc_plugin_x
  LIBRARY_OUTPUT_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/security-canary-plugin)

set(_sec_modes embedded unix tcp)
if(TARGET silc_mpi AND MPIEXEC_EXECUTABLE)
  list(APPEND _sec_modes mpi)
endif()
foreach(mode ${_sec_modes})
  add_test(NAME security_files_${mode}
           COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/files_attacks.sh ${mode}
                   $<TARGET_FILE:silc_cli> $<TARGET_FILE:silcd>
                   ${CMAKE_CURRENT_BINARY_DIR}/security-canary-plugin
                   ${CMAKE_CURRENT_BINARY_DIR}/security-files-${mode} "${MPIEXEC_EXECUTABLE}")
  set_tests_properties(security_files_${mode} PROPERTIES TIMEOUT 240
    ENVIRONMENT "${SILC_TEST_ENV};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1")
endforeach()
if(TEST security_files_mpi)
  set_tests_properties(security_files_mpi PROPERTIES RUN_SERIAL TRUE)
endif()
