# The recommended remote setup (docs/server.md, Security): a Unix-socket
# silcd reached through `ssh -N -L LOCAL.sock:SILCD.sock`, with an sshd of
# the test's own on 127.0.0.1 as the current user, keys and config in the
# build directory (ssh_tunnel.sh).  Skipped, saying why, when openssh-server
# or openssh-client is not installed.
if(NOT TARGET silcd OR NOT TARGET silc_cli)
  return()
endif()
add_test(NAME security_ssh_tunnel
         COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/ssh_tunnel.sh $<TARGET_FILE:silcd> $<TARGET_FILE:silc_cli>
                 ${CMAKE_CURRENT_BINARY_DIR}/security-ssh)
set_tests_properties(security_ssh_tunnel PROPERTIES TIMEOUT 120 SKIP_RETURN_CODE 77
  ENVIRONMENT "${SILC_TEST_ENV}")
