# bench/complex_helmholtz: a complex 2-D Helmholtz solve through SILC against
# UMFPACK called directly, SciPy and Octave (docs/complex.md), on
# examples/helmholtz's matrix (silc_helmholtz).  Links
# UMFPACK itself; built only when it is found.
find_path(BENCH_HZ_SS_INCLUDE umfpack.h PATHS /usr/include/suitesparse PATH_SUFFIXES suitesparse)
set(_hz_libs "")
set(_hz_missing "")
silc_find_libraries(_hz_libs _hz_missing BENCH_HZ_LIB_<name> umfpack amd suitesparseconfig)
if(NOT BENCH_HZ_SS_INCLUDE)
  list(APPEND _hz_missing umfpack.h)
endif()
if(_hz_missing)
  string(REPLACE ";" ", " _hz_missing "${_hz_missing}")
  message(STATUS "SILC: bench/complex_helmholtz skipped: ${_hz_missing} not found")
else()
  add_executable(complex_helmholtz complex_helmholtz.c)
  target_include_directories(complex_helmholtz PRIVATE ${BENCH_HZ_SS_INCLUDE})
  # silc_internal (the engine's objects, as silcd links them): the bench also
  # calls the large allocator (core/util) the suitesparse plugin hands UMFPACK.
  target_link_libraries(complex_helmholtz PRIVATE silc_helmholtz silc_internal ${_hz_libs} ${MATH_LIB})
endif()
