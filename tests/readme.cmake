# tests/readme.cmake -- README.md's code blocks run as written against this
# build (tests/readme.sh: what runs how, and the blocks marked skipped).  Not
# in a sanitizer build: the README's C program and Python are uninstrumented
# and cannot load ASan's libsilc (as test_install).
if(NOT SILC_SANITIZE AND TARGET silc_cli AND TARGET silcd AND SILC_SYSTEM_PYTHON)
  add_test(NAME test_readme COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/readme.sh ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(test_readme PROPERTIES ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 180)
endif()
