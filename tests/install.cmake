# tests/install.cmake -- SILC installed into a temporary prefix and used from
# an out-of-tree project (find_package and pkg-config; tests/install).  Not
# in a sanitizer build: an uninstrumented program cannot load ASan's libsilc.
if(NOT SILC_SANITIZE)
  add_test(NAME test_install COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/install/test_install.sh ${PROJECT_BINARY_DIR}
           ${PROJECT_SOURCE_DIR})
  set_tests_properties(test_install PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 300)
endif()
