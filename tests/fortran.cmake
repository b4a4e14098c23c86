# Tests of the Fortran binding (included from tests/CMakeLists.txt): the module's
# own test and the Fortran diffusion example, which exits 1 if its error exceeds
# the scheme's bound.  Both run embedded here; with SILC_SERVER set they run
# against silcd unchanged.
if(TARGET silc_fortran)
  add_executable(test_fortran ${CMAKE_CURRENT_LIST_DIR}/test_fortran.f90)
  target_link_libraries(test_fortran PRIVATE silc_fortran)
  if(CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
    # Round trips are checked for exact equality on purpose: nothing may change a bit.
    target_compile_options(test_fortran PRIVATE -Wno-compare-reals)
  endif()
  add_test(NAME test_fortran COMMAND test_fortran)
  add_test(NAME example_diffusion1d_fortran COMMAND diffusion1d_fortran)
  set_tests_properties(test_fortran example_diffusion1d_fortran PROPERTIES
    ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)
endif()
