# Remote mode (included from tests/CMakeLists.txt): the protocol's unit tests,
# the server's robustness, auth and stress tests, the fuzz run, the Python
# client, and the language suite and examples run again against a silcd that a
# ctest fixture starts on a Unix socket unique to this build directory.
if(NOT TARGET silcd)
  return()
endif()
find_package(Threads REQUIRED)

silc_add_test(test_protocol INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_protocol.c)
foreach(t test_remote test_remote_stress)
  silc_add_test(${t} INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/${t}.c)
  target_compile_definitions(${t} PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>")
  target_link_libraries(${t} PRIVATE Threads::Threads)
  set_tests_properties(${t} PROPERTIES TIMEOUT 120)
endforeach()

# The process model under faults: a plugin that dies on purpose (built in a
# directory of its own, which a server config names as core.plugin_path),
# and the test that crashes sessions, floods idle connections and kills
# clients and servers (tests/test_server.c).
add_library(silc_test_crash MODULE ${CMAKE_CURRENT_LIST_DIR}/server/crash_plugin.c)
target_include_directories(silc_test_crash PRIVATE ${PROJECT_SOURCE_DIR}/plugins)
set_target_properties(silc_test_crash PROPERTIES PREFIX "lib" OUTPUT_NAME silc_plugin_crash C_VISIBILITY_PRESET hidden
  LIBRARY_OUTPUT_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/crash-plugin)
silc_add_test(test_server INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_server.c)
target_compile_definitions(test_server PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>"
  CRASH_PLUGIN_DIR="${CMAKE_CURRENT_BINARY_DIR}/crash-plugin")
target_link_libraries(test_server PRIVATE Threads::Threads)
add_dependencies(test_server silc_test_crash silcd)
set_tests_properties(test_server PROPERTIES TIMEOUT 300)

# A backend silcd's config names that is not installed stops its start
# (issue 28): exit 2 naming the plugin; "name?" makes it optional.
add_test(NAME silcd_missing_plugin COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/silcd_missing_plugin.sh
  $<TARGET_FILE:silcd> ${CMAKE_CURRENT_BINARY_DIR})
set_tests_properties(silcd_missing_plugin PROPERTIES TIMEOUT 120)

# Interrupts (silc_cancel from a thread): embedded, inside a plugin call that
# polls host->cancelled() (the crash plugin), and over a private silcd.
silc_add_test(test_interrupt INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_interrupt.c)
target_compile_definitions(test_interrupt PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>"
  CRASH_PLUGIN_DIR="${CMAKE_CURRENT_BINARY_DIR}/crash-plugin")
target_link_libraries(test_interrupt PRIVATE Threads::Threads)
add_dependencies(test_interrupt silc_test_crash silcd)
set_tests_properties(test_interrupt PROPERTIES TIMEOUT 120)

# The frame decoder under a deterministic mutation fuzzer (always), and under
# libFuzzer when clang can build it (a short run; longer runs by hand).
add_executable(fuzz_frame ${CMAKE_CURRENT_LIST_DIR}/fuzz/fuzz_frame.c)
target_compile_definitions(fuzz_frame PRIVATE SILC_FUZZ_DRIVER=1)
target_link_libraries(fuzz_frame PRIVATE silc_internal)
add_test(NAME fuzz_frame COMMAND fuzz_frame 20000)
set_tests_properties(fuzz_frame PROPERTIES TIMEOUT 120)
find_program(SILC_CLANG clang)
if(SILC_CLANG AND NOT SILC_SANITIZE)
  execute_process(COMMAND ${SILC_CLANG} -fsanitize=fuzzer -x c - -o ${CMAKE_CURRENT_BINARY_DIR}/fuzz_probe
                  INPUT_FILE ${CMAKE_CURRENT_LIST_DIR}/fuzz/probe.c
                  RESULT_VARIABLE SILC_LIBFUZZER_RC OUTPUT_QUIET ERROR_QUIET)
  if(SILC_LIBFUZZER_RC EQUAL 0)
    set(_fz ${CMAKE_CURRENT_BINARY_DIR}/fuzz_frame_libfuzzer)
    set(_src ${CMAKE_CURRENT_LIST_DIR}/fuzz/fuzz_frame.c ${PROJECT_SOURCE_DIR}/core/client/protocol.c
             ${PROJECT_SOURCE_DIR}/core/store/envelope.c ${PROJECT_SOURCE_DIR}/core/store/value.c
             ${PROJECT_SOURCE_DIR}/core/util/util.c ${PROJECT_SOURCE_DIR}/core/util/largealloc.c)
    list(TRANSFORM SILC_CORE_DIRS PREPEND -I OUTPUT_VARIABLE _core_inc)
    add_custom_command(OUTPUT ${_fz}
      COMMAND ${SILC_CLANG} -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined
              -I${PROJECT_SOURCE_DIR}/core/include ${_core_inc}
              -I${PROJECT_SOURCE_DIR}/plugins ${_src} -lm -o ${_fz}
      DEPENDS ${_src} ${SILC_FUZZ_HEADERS} VERBATIM)
    add_custom_target(fuzz_frame_libfuzzer ALL DEPENDS ${_fz})
    # libFuzzer adds what it finds to its first directory: a scratch one.
    file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz-corpus)
    add_test(NAME fuzz_frame_libfuzzer
             COMMAND ${_fz} -runs=20000 -seed=1 -max_len=4096
                     ${CMAKE_CURRENT_BINARY_DIR}/fuzz-corpus ${CMAKE_CURRENT_LIST_DIR}/fuzz/corpus)
    set_tests_properties(fuzz_frame_libfuzzer PROPERTIES TIMEOUT 120)
  else()
    message(STATUS "SILC: clang cannot build libFuzzer targets; fuzz_frame runs the built-in mutator only")
  endif()
endif()

# A server for the remote variants: one per build directory, on a socket path
# short enough for sun_path wherever the build directory lies.
string(MD5 _silcd_hash "${CMAKE_BINARY_DIR}")
string(SUBSTRING "${_silcd_hash}" 0 12 _silcd_hash)
set(SILC_TEST_SOCKET "/tmp/silcd-test-${_silcd_hash}.sock")
set(_state ${CMAKE_CURRENT_BINARY_DIR}/silcd-fixture)
add_test(NAME silcd_start COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/remote_server.sh start
         $<TARGET_FILE:silcd> ${SILC_TEST_SOCKET} ${_state})
add_test(NAME silcd_stop COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/remote_server.sh stop
         $<TARGET_FILE:silcd> ${SILC_TEST_SOCKET} ${_state})
# Its wisdom file is its operator's (tune.wisdom is a server setting): kept
# in its state directory, not in $HOME.
set_tests_properties(silcd_start PROPERTIES FIXTURES_SETUP silcd
                     ENVIRONMENT "${SILC_TEST_ENV};SILC_WISDOM=${_state}/wisdom")
set_tests_properties(silcd_stop PROPERTIES FIXTURES_CLEANUP silcd)

set(_remote_env "${SILC_TEST_ENV};SILC_SERVER=unix:${SILC_TEST_SOCKET}")
foreach(t test_api test_lang test_truth test_examples test_cloth_example)
  if(TARGET ${t})
    add_test(NAME ${t}_remote COMMAND ${t})
    set_tests_properties(${t}_remote PROPERTIES ENVIRONMENT "${_remote_env}" TIMEOUT 600
                         FIXTURES_REQUIRED silcd)
  endif()
endforeach()
add_test(NAME example_diffusion1d_remote COMMAND diffusion1d 50 100 0.5)
add_test(NAME example_diffusion2d_remote
         COMMAND diffusion2d -n 30 -s 5 -o ${CMAKE_CURRENT_BINARY_DIR}/diffusion2d_remote.pgm)
add_test(NAME test_cli_remote COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/test_cli.sh $<TARGET_FILE:silc_cli>)
set_tests_properties(example_diffusion1d_remote example_diffusion2d_remote test_cli_remote PROPERTIES
  ENVIRONMENT "${_remote_env}" TIMEOUT 600 FIXTURES_REQUIRED silcd)

# The Python client speaks the protocol on its own; it runs with the system
# interpreter, whose numpy comes from Debian's python3-numpy.
find_program(SILC_SYSTEM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(SILC_SYSTEM_PYTHON)
  add_test(NAME test_python COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/test_python.py
           ${PROJECT_SOURCE_DIR}/bindings/python)
  set_tests_properties(test_python PROPERTIES ENVIRONMENT "${_remote_env}" TIMEOUT 120
                       FIXTURES_REQUIRED silcd)
  # Ctrl-C in the REPL (through a pseudo-terminal) and cancel from the
  # Python client, against a silcd of its own; embedded Python too where
  # the interpreter can load libsilc (not under a sanitizer).
  if(TARGET silc_cli)
    set(_interrupt_env "${SILC_TEST_ENV}")
    if(NOT SILC_SANITIZE)
      list(APPEND _interrupt_env "SILC_LIBRARY=$<TARGET_FILE:silc>")
    endif()
    add_test(NAME test_interrupt_py COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/test_interrupt.py
             $<TARGET_FILE:silc_cli> $<TARGET_FILE:silcd> ${PROJECT_SOURCE_DIR}/bindings/python)
    set_tests_properties(test_interrupt_py PROPERTIES ENVIRONMENT "${_interrupt_env}" TIMEOUT 120)
  endif()
  # The same test embedded: libsilc in the interpreter through ctypes (not
  # in a sanitizer build: an uninstrumented interpreter cannot load ASan's
  # libsilc).
  if(NOT SILC_SANITIZE)
    add_test(NAME test_python_embedded COMMAND ${SILC_SYSTEM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/test_python.py
             ${PROJECT_SOURCE_DIR}/bindings/python)
    set_tests_properties(test_python_embedded PROPERTIES
                         ENVIRONMENT "${SILC_TEST_ENV};SILC_LIBRARY=$<TARGET_FILE:silc>" TIMEOUT 120)
  endif()
endif()

# Complex values in the core (issue 31): store, properties, and the C API
# embedded and through a private silcd.
silc_add_test(test_complex_core INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_complex_core.c)
target_compile_definitions(test_complex_core PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>"
  ABI_PLUGIN_DIR="${PROJECT_BINARY_DIR}/tests/abi")
add_dependencies(test_complex_core silcd abi_old_minor abi_takes_complex)
set_tests_properties(test_complex_core PROPERTIES TIMEOUT 120)
