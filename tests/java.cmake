# tests/java.cmake -- the Java client (bindings/java) against silcd: the
# fixture's server on a Unix socket, then a TCP server with a token that the
# script starts itself (tests/java/test_java.sh).  Skipped without a JDK.
if(TARGET silc_java AND TARGET silcd)
  include(UseJava)
  set(CMAKE_JAVA_COMPILE_FLAGS -Xlint:all -Werror)
  add_jar(silc_java_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/java/TestClient.java INCLUDE_JARS silc_java
          OUTPUT_NAME silc_java_test)
  get_target_property(_test_jar silc_java_test JAR_FILE)
  add_test(NAME test_java COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/java/test_java.sh ${Java_JAVA_EXECUTABLE}
           ${SILC_JAVA_JAR} ${_test_jar} $<TARGET_FILE:silcd>)
  set_tests_properties(test_java PROPERTIES ENVIRONMENT "${_remote_env}" TIMEOUT 120 FIXTURES_REQUIRED silcd)
endif()
