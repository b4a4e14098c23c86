# Replies a client gets (docs/security.md, "Replies a client gets"; issue
# 33): clients.py's fake silcd on a Unix socket in the build directory sends
# each hostile reply -- CSR that breaks its structure, a descriptor with a
# bad nnz, a length that disagrees with its descriptor, a TEXT header
# claiming 1 GiB, a 240 KB band value of 30000 x 30000, a value over the
# client's cap, silence at the hello, before a reply, inside a frame and
# after an EXEC, an unknown opcode, a hang-up mid-frame, a complex value whose
# arrays have a real value's size, a complex value sent to a plain GET -- to
# the C client, the Python client and the Java client (one check per reply
# per client), and the CSR and complex ones to the Fortran binding.
if(NOT SILC_SYSTEM_PYTHON)
  message(STATUS "SILC: client attack tests skipped (/usr/bin/python3 missing)")
  return()
endif()
set(_clients_dir ${CMAKE_CURRENT_BINARY_DIR}/security-clients)
set(_clients_py ${CMAKE_CURRENT_LIST_DIR}/clients.py)

# The C runner (a program of libsilc's public API, not a test of its own).
add_executable(clients_c ${CMAKE_CURRENT_LIST_DIR}/clients_c.c)
target_include_directories(clients_c PRIVATE ${PROJECT_SOURCE_DIR}/core/include)
target_link_libraries(clients_c PRIVATE silc)
add_test(NAME security_clients_c COMMAND ${SILC_SYSTEM_PYTHON} ${_clients_py} c ${_clients_dir}
         $<TARGET_FILE:clients_c>)
add_test(NAME security_clients_python COMMAND ${SILC_SYSTEM_PYTHON} ${_clients_py} python ${_clients_dir}
         ${PROJECT_SOURCE_DIR}/bindings/python)
set_tests_properties(security_clients_c security_clients_python PROPERTIES
  ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 120)

if(TARGET silc_fortran)
  add_executable(clients_fortran ${CMAKE_CURRENT_LIST_DIR}/clients_fortran.f90)
  target_link_libraries(clients_fortran PRIVATE silc_fortran)
  add_test(NAME security_clients_fortran COMMAND ${SILC_SYSTEM_PYTHON} ${_clients_py} fortran
           ${_clients_dir} $<TARGET_FILE:clients_fortran>)
  set_tests_properties(security_clients_fortran PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 120)
endif()

if(TARGET silc_java)
  include(UseJava)
  set(CMAKE_JAVA_COMPILE_FLAGS -Xlint:all -Werror)
  add_jar(silc_clients_java SOURCES ${CMAKE_CURRENT_LIST_DIR}/ClientsJava.java INCLUDE_JARS silc_java
          OUTPUT_NAME silc_clients_java)
  get_target_property(_clients_jar silc_clients_java JAR_FILE)
  add_test(NAME security_clients_java COMMAND ${SILC_SYSTEM_PYTHON} ${_clients_py} java ${_clients_dir}
           ${Java_JAVA_EXECUTABLE} -cp ${SILC_JAVA_JAR}:${_clients_jar} ClientsJava)
  set_tests_properties(security_clients_java PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 180)
else()
  message(STATUS "SILC: Java client attack tests skipped (no JDK >= 17)")
endif()
