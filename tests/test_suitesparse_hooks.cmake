# test_suitesparse_hooks: plugin-suitesparse's SuiteSparse_config hooks (huge
# pages for the libraries' large blocks), once in a program that leaves the
# hooks alone and once in one that set its own (which must be kept).  Links
# SuiteSparse_config itself and the engine statically (it asks the large
# allocator in core/util which blocks are its own); built only with the plugin.
if(TARGET silc_plugin_suitesparse)
  silc_add_test(test_suitesparse_hooks INTERNAL SOURCES test_suitesparse_hooks.c)
  target_include_directories(test_suitesparse_hooks PRIVATE ${SUITESPARSE_INCLUDE_DIR})
  target_link_libraries(test_suitesparse_hooks PRIVATE silc_helmholtz ${SUITESPARSE_suitesparseconfig_LIBRARY})
  add_dependencies(test_suitesparse_hooks silc_plugin_suitesparse)
  # (silc_add_test registered the default case as test_suitesparse_hooks)
  add_test(NAME test_suitesparse_hooks_own COMMAND test_suitesparse_hooks own)
  set_tests_properties(test_suitesparse_hooks_own PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)
endif()
