# bench/mumps_solve (included from bench/CMakeLists.txt): MUMPS's solve phase
# called directly (sequential dmumps_c and smumps_c, the static archives the
# plugin links), the baseline for SILC's mumps backend in a loop that reuses
# one factorization (docs/backends.md, the diffusion loop).  Built when the
# sequential mumps plugin is: it links what plugin-mumps/CMakeLists.txt found
# (cached there), so the search for MUMPS is written once.
if(TARGET silc_plugin_mumps)
  add_executable(mumps_solve mumps_solve.c)
  target_include_directories(mumps_solve PRIVATE ${MUMPS_INCLUDE_DIR})
  target_link_libraries(mumps_solve PRIVATE
    ${MUMPS_dmumps_seq_STATIC} ${MUMPS_smumps_seq_STATIC} ${MUMPS_mumps_common_seq_STATIC}
    ${MUMPS_pord_seq_STATIC} ${MUMPS_mpiseq_seq_STATIC}
    ${MUMPS_DEP_esmumps} ${MUMPS_DEP_scotch} ${MUMPS_DEP_scotcherr} ${MUMPS_DEP_lapack}
    ${MUMPS_DEP_blas} ${MUMPS_DEP_gfortran} ${MATH_LIB})
else()
  message(STATUS "SILC: bench/mumps_solve skipped: the sequential mumps plugin is not built")
endif()
