# Fuzzing (included from tests/CMakeLists.txt): the language (fuzz_lang: text
# through lexer, parser and evaluator) and the config reader (fuzz_config),
# each under a deterministic mutation driver on any compiler, with a fixed
# number of inputs from the committed seed corpora, and under libFuzzer with
# ASan and UBSan when clang can build it (a short run here; bench/fuzz.sh runs
# them longer).  The frame fuzzer lives in remote.cmake beside the server.
set(_fz_dir ${CMAKE_CURRENT_LIST_DIR}/fuzz)

# Iterations: chosen so that each test takes about 15 s on 2 busy cores under
# ASan+UBSan and 2 s without (docs/reliability.md, "Fuzzing").
add_executable(fuzz_lang ${_fz_dir}/fuzz_lang.c)
target_compile_definitions(fuzz_lang PRIVATE SILC_FUZZ_DRIVER=1)
target_link_libraries(fuzz_lang PRIVATE silc_internal)
add_test(NAME fuzz_lang COMMAND fuzz_lang 20000 ${_fz_dir}/corpus-lang)
add_executable(fuzz_config ${_fz_dir}/fuzz_config.c)
target_compile_definitions(fuzz_config PRIVATE SILC_FUZZ_DRIVER=1)
target_link_libraries(fuzz_config PRIVATE silc_internal)
add_test(NAME fuzz_config COMMAND fuzz_config 20000 ${_fz_dir}/corpus-config)
set_tests_properties(fuzz_lang fuzz_config PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 120)
if(SILC_SANITIZE)
  # CI's ASAN_OPTIONS unwind slowly on every malloc (for MPI's frames in the
  # leak suppressions), which makes 20000 inputs take minutes; the fuzz
  # drivers load no MPI code, so they unwind fast.
  set_property(TEST fuzz_lang fuzz_config APPEND PROPERTY ENVIRONMENT
               "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:fast_unwind_on_malloc=1")
endif()

find_program(SILC_CLANG clang)
if(NOT SILC_CLANG OR SILC_SANITIZE)
  return()
endif()
if(NOT DEFINED SILC_LIBFUZZER_RC)   # remote.cmake may have probed already
  execute_process(COMMAND ${SILC_CLANG} -fsanitize=fuzzer -x c - -o ${CMAKE_CURRENT_BINARY_DIR}/fuzz_probe
                  INPUT_FILE ${_fz_dir}/probe.c
                  RESULT_VARIABLE SILC_LIBFUZZER_RC OUTPUT_QUIET ERROR_QUIET)
endif()
if(NOT SILC_LIBFUZZER_RC EQUAL 0)
  message(STATUS "SILC: clang cannot build libFuzzer targets; fuzz_lang and fuzz_config run the built-in mutator only")
  return()
endif()

# The whole engine, compiled by clang with the fuzzer's instrumentation: the
# sources and definitions silc_objects has (core/CMakeLists.txt), linked
# straight into each harness.
file(GLOB _fz_engine CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/plugin-reference/*.c)
list(PREPEND _fz_engine ${SILC_CORE_SOURCES})
list(TRANSFORM SILC_CORE_DIRS PREPEND -I OUTPUT_VARIABLE _core_inc)
set(_fz_inih_flags)
foreach(d ${INIH_INCLUDE_DIRS})
  list(APPEND _fz_inih_flags -I${d})
endforeach()
foreach(h lang config)
  set(_fz ${CMAKE_CURRENT_BINARY_DIR}/fuzz_${h}_libfuzzer)
  add_custom_command(OUTPUT ${_fz}
    COMMAND ${SILC_CLANG} -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined
            -fno-sanitize-recover=undefined
            -DSILC_REFERENCE_BUILTIN=1 -DSILC_PLUGIN_BUILD_DIR="${SILC_PLUGIN_BUILD_DIR}"
            -DSILC_PLUGIN_INSTALL_DIR="${SILC_PLUGIN_INSTALL_DIR}"
            -I${PROJECT_SOURCE_DIR}/core/include ${_core_inc}
            -I${PROJECT_SOURCE_DIR}/plugins -I${PROJECT_SOURCE_DIR}/plugin-reference ${_fz_inih_flags}
            ${_fz_dir}/fuzz_${h}.c ${_fz_engine} ${INIH_LDFLAGS} -ldl -lm -lpthread -o ${_fz}
    DEPENDS ${_fz_dir}/fuzz_${h}.c ${_fz_engine} ${SILC_FUZZ_HEADERS} VERBATIM)
  add_custom_target(fuzz_${h}_libfuzzer ALL DEPENDS ${_fz})
  # libFuzzer adds what it finds to its first directory: a scratch one.
  file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/fuzz-corpus-${h})
endforeach()
add_test(NAME fuzz_lang_libfuzzer
         COMMAND ${CMAKE_CURRENT_BINARY_DIR}/fuzz_lang_libfuzzer -runs=20000 -seed=1 -max_len=4096
                 -timeout=10 -rss_limit_mb=2048 -dict=${_fz_dir}/lang.dict
                 ${CMAKE_CURRENT_BINARY_DIR}/fuzz-corpus-lang ${_fz_dir}/corpus-lang)
add_test(NAME fuzz_config_libfuzzer
         COMMAND ${CMAKE_CURRENT_BINARY_DIR}/fuzz_config_libfuzzer -runs=20000 -seed=1 -max_len=1024
                 -timeout=10 -rss_limit_mb=2048
                 ${CMAKE_CURRENT_BINARY_DIR}/fuzz-corpus-config ${_fz_dir}/corpus-config)
set_tests_properties(fuzz_lang_libfuzzer fuzz_config_libfuzzer PROPERTIES
  ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 300)
