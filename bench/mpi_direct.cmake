# bench/mpi_direct (included from bench/CMakeLists.txt): the baseline for the
# MPI server bench -- the same PETSc solves (hypre CG, GMRES + block Jacobi,
# MUMPS LU) called directly by a small MPI program, no SILC.  Built only when
# PETSc and MPI are found (the top-level CMakeLists.txt, SILC_PETSC_MISSING).
# Not a test; run it with mpirun (docs/distributed.md).
if(SILC_PETSC_MISSING)
  message(STATUS "SILC: bench/mpi_direct skipped: ${SILC_PETSC_MISSING} not found (apt-get install petsc-dev)")
else()
  add_executable(mpi_direct mpi_direct.c)
  target_link_libraries(mpi_direct PRIVATE PkgConfig::PETSC MPI::MPI_C)
  # -method dmumps calls MPI MUMPS itself (the library PETSc's MUMPS is)
  find_library(BENCH_DMUMPS_LIBRARY dmumps)
  find_path(BENCH_DMUMPS_INCLUDE_DIR dmumps_c.h)
  if(BENCH_DMUMPS_LIBRARY AND BENCH_DMUMPS_INCLUDE_DIR)
    target_include_directories(mpi_direct PRIVATE ${BENCH_DMUMPS_INCLUDE_DIR})
    target_link_libraries(mpi_direct PRIVATE ${BENCH_DMUMPS_LIBRARY})
    target_compile_definitions(mpi_direct PRIVATE BENCH_HAVE_DMUMPS=1)
  endif()
endif()
