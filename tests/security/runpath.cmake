# The dynamic loader's search path (docs/security.md, "Files"): no program or
# library of the build tree has an empty or relative RUNPATH entry, which
# would make the loader search the current directory of whoever runs it, and
# silc, silcd and every plugin's dependencies, planted as a canary library in
# the current directory, are not loaded from there (runpath.sh).
if(NOT TARGET silc_cli OR NOT TARGET silcd OR NOT TARGET silc_security_canary)
  return()
endif()
add_test(NAME security_runpath
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/runpath.sh ${PROJECT_BINARY_DIR}
                 $<TARGET_FILE:silc_security_canary> ${CMAKE_CURRENT_BINARY_DIR}/security-runpath
                 $<TARGET_FILE:silc_cli> $<TARGET_FILE:silcd>)
set_tests_properties(security_runpath PROPERTIES TIMEOUT 120 ENVIRONMENT "${SILC_TEST_ENV}")
