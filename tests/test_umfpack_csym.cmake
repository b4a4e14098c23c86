# test_umfpack_csym: suitesparse.umfpack's complex symmetric path
# (UMFPACK_A) against UMFPACK called directly; links UMFPACK itself, so it
# is built only with the suitesparse plugin.
if(TARGET silc_plugin_suitesparse)
  silc_add_test(test_umfpack_csym SOURCES test_umfpack_csym.c)
  target_include_directories(test_umfpack_csym PRIVATE ${SUITESPARSE_INCLUDE_DIR})
  target_link_libraries(test_umfpack_csym PRIVATE silc_helmholtz ${SUITESPARSE_umfpack_LIBRARY}
    ${SUITESPARSE_amd_LIBRARY} ${SUITESPARSE_suitesparseconfig_LIBRARY})
  add_dependencies(test_umfpack_csym silc_plugin_suitesparse)
endif()
