# bench/backends: SILC's direct-solver backends against the same libraries
# called directly (so it links UMFPACK, KLU, CHOLMOD and sequential MUMPS
# itself), SciPy and Octave.  Built only when those libraries are found.
find_path(BENCH_SS_INCLUDE umfpack.h PATHS /usr/include/suitesparse PATH_SUFFIXES suitesparse)
find_path(BENCH_MUMPS_INCLUDE dmumps_c.h PATH_SUFFIXES mumps_seq)
set(_bench_libs "")
set(_bench_missing "")
silc_find_libraries(_bench_libs _bench_missing BENCH_LIB_<name>
  umfpack klu cholmod amd colamd suitesparseconfig dmumps_seq mumps_common_seq mpiseq_seq)
if(NOT BENCH_SS_INCLUDE)
  list(APPEND _bench_missing umfpack.h)
endif()
if(NOT BENCH_MUMPS_INCLUDE)
  list(APPEND _bench_missing dmumps_c.h)
endif()
if(_bench_missing)
  string(REPLACE ";" ", " _bench_missing "${_bench_missing}")
  message(STATUS "SILC: bench/backends skipped: ${_bench_missing} not found")
else()
  add_executable(backends backends.c)
  target_include_directories(backends PRIVATE ${PROJECT_SOURCE_DIR}/tests
    ${BENCH_SS_INCLUDE} ${BENCH_MUMPS_INCLUDE})
  get_filename_component(_bench_matrices ${PROJECT_SOURCE_DIR}/../shared/matrices ABSOLUTE)
  target_compile_definitions(backends PRIVATE SILC_SHARED_MATRICES="${_bench_matrices}")
  # silc_diffusion: the main example's matrices and field for --only diffusion.
  target_link_libraries(backends PRIVATE silc silc_diffusion ${_bench_libs} ${MATH_LIB})
endif()
