# Cross-plugin tests of issue 3 (included by tests/CMakeLists.txt):
#   test_plugin_order  all plugins loaded in two orders into one process each
#                      (internal: drives the engine's loader directly)
#   test_configs       one silc script under three configuration files
# test_conformance is a plain test in the main list.
silc_add_test(test_plugin_order SOURCES test_plugin_order.c INTERNAL)
target_compile_definitions(test_plugin_order PRIVATE SILC_PLUGIN_DIR="${SILC_PLUGIN_BUILD_DIR}")
foreach(p lapack suitesparse mumps petsc lis-style)
  if(TARGET silc_plugin_${p})
    add_dependencies(test_plugin_order silc_plugin_${p})
    if(TARGET test_conformance)
      add_dependencies(test_conformance silc_plugin_${p})
    endif()
  endif()
endforeach()

add_test(NAME test_configs
  COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/test_configs.sh $<TARGET_FILE:silc_cli>
          ${SILC_SHARED_MATRICES} ${CMAKE_CURRENT_SOURCE_DIR}/conformance)
set_tests_properties(test_configs PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)

# The Octave comparison (tests/conformance/octave/README.md): suite.m through
# `silc run` must print what Octave 7.3 printed for it (suite.octave-truth.txt).
if(TARGET silc_cli)
  add_test(NAME test_octave
    COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/conformance/octave/run.sh $<TARGET_FILE:silc_cli>)
  set_tests_properties(test_octave PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 60)
endif()
