# bench/limit: SpMV against a plain C loop and the dense solve against
# LAPACKE_dgesv (it calls LAPACKE itself, so it needs what plugin-lapack
# needs; skipped with a message otherwise).
if(LAPACKE_INCLUDE_DIR AND LAPACKE_LIBRARY AND OPENBLAS_LIBRARY)
  add_executable(limit limit.c)
  target_include_directories(limit PRIVATE ${LAPACKE_INCLUDE_DIR})
  target_link_libraries(limit PRIVATE silc silc_diffusion ${LAPACKE_LIBRARY} ${OPENBLAS_LIBRARY})
else()
  message(STATUS "SILC: bench/limit skipped: LAPACKE or OpenBLAS not found")
endif()
