# Values handed to SILC (docs/security.md, "Values handed to SILC"): bad
# envelopes PUT embedded and to a silcd of the test's own on a Unix socket in
# the build directory (values_put.c), crafted HDF5 files loaded (values_h5.c,
# written with the HDF5 C API by the test; with silcd, also loaded under a
# session's --max-session-bytes), and Matrix Market files by the
# format's rules, one table row per case (values_mm.c).
if(TARGET silcd)
  silc_add_test(security_values_put INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/values_put.c)
  target_compile_definitions(security_values_put PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>")
  add_dependencies(security_values_put silcd)
  set_tests_properties(security_values_put PROPERTIES TIMEOUT 120)
endif()

silc_add_test(security_values_mm SOURCES ${CMAKE_CURRENT_LIST_DIR}/values_mm.c)
set_tests_properties(security_values_mm PROPERTIES TIMEOUT 60)

find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(SILC_TEST_HDF5 QUIET IMPORTED_TARGET hdf5-serial)
endif()
if(SILC_TEST_HDF5_FOUND)
  silc_add_test(security_values_h5 INTERNAL SOURCES ${CMAKE_CURRENT_LIST_DIR}/values_h5.c)
  target_link_libraries(security_values_h5 PRIVATE PkgConfig::SILC_TEST_HDF5)
  set_tests_properties(security_values_h5 PROPERTIES TIMEOUT 120)
  if(TARGET silcd) # the session budget's cases, against a silcd of the test's own
    target_compile_definitions(security_values_h5 PRIVATE SILCD_PATH="$<TARGET_FILE:silcd>")
    add_dependencies(security_values_h5 silcd)
  endif()
endif()
